"""Package lookup as ROS does it (issue 19): AMENT_PREFIX_PATH, ROS_PACKAGE_PATH, --package-dir,
the enclosing package by its package.xml name, and confinement in symlink-install trees.

Before armcli.io.packages: `$(find)` and `package://` ignored AMENT_PREFIX_PATH (what a
sourced ROS 2 workspace sets), a clone directory not named like its package was not found,
and every `file://` mesh of a colcon --symlink-install tree was "outside the allowed
directories" (20 false errors on MoveIt's panda).
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from armcli.io.packages import PackageLookup, crawl, real_roots
from armcli.urdf.meshes import confined, resolve
from tests.helpers import ARM_PACKAGE, GRIPPER_PACKAGE, ROS_WS_SRC, symlink_install


@pytest.fixture
def prefix(tmp_path: Path) -> Path:
    return symlink_install(ROS_WS_SRC, tmp_path / "install")


def no_env(**kw: object) -> PackageLookup:
    """A lookup that ignores this machine's ROS variables unless given."""
    base: dict[str, object] = {"ament_prefixes": (), "ros_package_path": ()}
    return PackageLookup(**{**base, **kw})  # type: ignore[arg-type]


def test_ament_prefix_gives_share_dir_unresolved(prefix: Path) -> None:
    # ament_index_python returns <prefix>/share/NAME as is: xacro writes that path out.
    found = no_env(ament_prefixes=(prefix,)).find(ARM_PACKAGE)
    assert found == prefix / "share" / ARM_PACKAGE
    assert no_env(ament_prefixes=(prefix,)).find("arm_clone") is None  # not a package name


def test_ament_prefix_path_from_environment(prefix: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(
        "AMENT_PREFIX_PATH", os.pathsep.join([str(prefix.parent / "x"), str(prefix)])
    )
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    assert PackageLookup().find(GRIPPER_PACKAGE) == prefix / "share" / GRIPPER_PACKAGE


def test_ros_package_path_crawl_uses_package_xml_names(tmp_path: Path) -> None:
    lookup = no_env(ros_package_path=(ROS_WS_SRC,))
    assert lookup.find(ARM_PACKAGE) == ROS_WS_SRC / "arm_clone"
    assert lookup.find("arm_clone") is None  # a directory name is not a package name
    ignored = tmp_path / "ws"
    (ignored / "skipped" / "pkg").mkdir(parents=True)
    (ignored / "skipped" / "pkg" / "package.xml").write_text(
        "<package><name>hidden</name></package>"
    )
    assert crawl(ignored) == {"hidden": ignored / "skipped" / "pkg"}
    (ignored / "skipped" / "COLCON_IGNORE").touch()
    crawl.cache_clear()
    assert no_env(ros_package_path=(ignored,)).find("hidden") is None


def test_order_package_dir_then_ament_then_crawl_then_enclosing(
    prefix: Path, tmp_path: Path
) -> None:
    mine = tmp_path / "mine"
    mine.mkdir()
    near = ROS_WS_SRC / "arm_clone" / "urdf" / "demo_arm.urdf.xacro"
    assert no_env().find(ARM_PACKAGE, near) == ROS_WS_SRC / "arm_clone"  # enclosing
    crawled = no_env(ros_package_path=(ROS_WS_SRC,))
    assert crawled.find(ARM_PACKAGE, near) == ROS_WS_SRC / "arm_clone"
    both = no_env(ament_prefixes=(prefix,), ros_package_path=(ROS_WS_SRC,))
    assert both.find(ARM_PACKAGE, near) == prefix / "share" / ARM_PACKAGE
    given = no_env(package_dirs={ARM_PACKAGE: mine}, ament_prefixes=(prefix,))
    assert given.find(ARM_PACKAGE, near) == mine
    assert no_env().find(GRIPPER_PACKAGE, near) is None  # not enclosing, not on any path


def test_symlink_install_real_roots_reach_the_source_package(prefix: Path) -> None:
    share = prefix / "share" / ARM_PACKAGE
    assert real_roots(share) == (share.resolve(), (ROS_WS_SRC / "arm_clone").resolve())
    assert real_roots(ROS_WS_SRC / "arm_clone") == ((ROS_WS_SRC / "arm_clone").resolve(),)


def test_file_uri_in_symlink_install_is_allowed(prefix: Path, tmp_path: Path) -> None:
    # What `file://$(find pkg)/meshes/...` expands to with AMENT_PREFIX_PATH set.
    lookup = no_env(ament_prefixes=(prefix,))
    urdf_dir = tmp_path / "elsewhere"
    urdf_dir.mkdir()
    mesh = prefix / "share" / ARM_PACKAGE / "meshes" / "upper.stl"
    uri = f"file://{mesh}"
    assert resolve(uri, urdf_dir, lookup) == mesh
    assert confined(uri, mesh, urdf_dir, lookup)
    package_uri = f"package://{GRIPPER_PACKAGE}/meshes/finger.stl"
    finger = resolve(package_uri, urdf_dir, lookup)
    assert finger is not None and finger.is_file()
    assert confined(package_uri, finger, urdf_dir, lookup)
    # Without the prefix on AMENT_PREFIX_PATH the same file is not the package's: refused.
    assert not confined(uri, mesh, urdf_dir, no_env())


def test_a_four_slash_file_uri_is_the_same_file(prefix: Path, tmp_path: Path) -> None:
    """COBOTTA writes `file:////abs/path`: the same file as `file:///abs/path` (RFC 8089's
    empty authority plus an absolute path), found in its package, not reported missing."""
    lookup = no_env(ament_prefixes=(prefix,))
    urdf_dir = tmp_path / "elsewhere"
    urdf_dir.mkdir()
    mesh = prefix / "share" / ARM_PACKAGE / "meshes" / "upper.stl"
    uri = f"file:///{mesh}"
    assert uri.startswith("file:////")
    assert resolve(uri, urdf_dir, lookup) == mesh == resolve(f"file://{mesh}", urdf_dir, lookup)
    assert confined(uri, mesh, urdf_dir, lookup)


def test_confinement_not_widened(prefix: Path, tmp_path: Path) -> None:
    lookup = no_env(ament_prefixes=(prefix,))
    urdf_dir = tmp_path / "robot"
    urdf_dir.mkdir()
    share = prefix / "share" / ARM_PACKAGE
    (share / "meshes" / "evil.stl").symlink_to("/etc/passwd")
    for uri in (
        f"package://{ARM_PACKAGE}/meshes/evil.stl",
        f"file://{share}/meshes/evil.stl",
        "file:///etc/passwd",
        f"file://{tmp_path}/loose.stl",  # no package holds it
    ):
        path = resolve(uri, urdf_dir, lookup)
        assert path is not None and not confined(uri, path, urdf_dir, lookup), uri


def test_package_xml_symlinked_elsewhere_is_not_a_root(prefix: Path, tmp_path: Path) -> None:
    # A package.xml symlink only widens the roots to a directory whose package.xml has the
    # same name: a hostile install cannot point it at "/" or another package.
    other = tmp_path / "other"
    other.mkdir()
    (other / "package.xml").write_text("<package><name>other</name></package>")
    share = prefix / "share" / GRIPPER_PACKAGE
    (share / "package.xml").unlink()
    (share / "package.xml").symlink_to(other / "package.xml")
    assert real_roots(share) == (share.resolve(),)


def test_owner_of_a_path(prefix: Path) -> None:
    lookup = no_env(ament_prefixes=(prefix,))
    share = prefix / "share" / ARM_PACKAGE
    assert lookup.owner(share / "meshes" / "base.stl") == share
    assert lookup.owner(Path("/etc/passwd")) is None


def test_json_round_trip_fixes_the_environment(
    prefix: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(ROS_WS_SRC))
    lookup = PackageLookup({"x": Path("/x")})
    copy = PackageLookup.from_json(lookup.to_json())
    monkeypatch.delenv("AMENT_PREFIX_PATH")
    assert copy.prefixes() == (prefix,) and copy.crawl_paths() == (ROS_WS_SRC,)
    assert copy.package_dirs == {"x": Path("/x")}
    assert copy.known()[GRIPPER_PACKAGE] == prefix / "share" / GRIPPER_PACKAGE


def _root_package(tmp_path: Path) -> Path:
    """An install prefix registering package `evil` whose share dir is a symlink to `/`."""
    prefix = tmp_path / "evil_prefix"
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "evil").write_text("")
    (prefix / "share" / "evil").symlink_to("/")
    return prefix


def test_a_package_root_is_never_slash_or_a_system_dir(tmp_path: Path) -> None:
    """Issue 27: share/evil -> / made every host file "inside the package"."""
    prefix = _root_package(tmp_path)
    lookup = no_env(ament_prefixes=(prefix,))
    root = lookup.find("evil")
    assert root is not None
    assert real_roots(root) == ()
    uri = "package://evil/etc/passwd"
    path = resolve(uri, tmp_path, lookup)
    assert path is not None and not confined(uri, path, tmp_path, lookup)


def test_safe_xacro_reads_nothing_through_a_slash_package(tmp_path: Path) -> None:
    from armcli.errors import XacroRefusedError
    from armcli.xacro.args import XacroInputs
    from armcli.xacro.safe import expand_safe

    prefix = _root_package(tmp_path)
    secret = tmp_path / "host" / "secret.yaml"
    secret.parent.mkdir()
    secret.write_text("token: s3cret\n")
    robot = tmp_path / "robot"
    robot.mkdir()
    top = robot / "r.urdf.xacro"
    top.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        f'<xacro:property name="y" value="${{xacro.load_yaml(\'$(find evil){secret}\')}}"/>'
        "<link name=\"${y['token']}\"/></robot>"
    )
    inputs = XacroInputs(packages=no_env(ament_prefixes=(prefix,)))
    with pytest.raises(XacroRefusedError, match="outside the allowed directories"):
        expand_safe(top, [robot], inputs=inputs)
