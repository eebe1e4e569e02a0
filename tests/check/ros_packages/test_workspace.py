"""Finding packages under DIR: package.xml, colcon's ignore markers, no way out of DIR."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from armcli.check.ros_packages.workspace import discover, has_packages
from tests.check.ros_packages.workspaces import findings, package_rules

MANIFEST = """<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.0.0</version>
  <description>d</description>
  <maintainer email="a@b.c">a</maintainer>
  <license>MIT</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <exec_depend>rviz2</exec_depend>
  <export><build_type>ament_cmake</build_type></export>
</package>
"""


def package(root: Path, rel: str, name: str) -> Path:
    d = root / rel
    d.mkdir(parents=True, exist_ok=True)
    (d / "package.xml").write_text(MANIFEST.format(name=name))
    return d


def test_packages_by_manifest_name_ignores_and_duplicates(tmp_path: Path) -> None:
    package(tmp_path, "src/a_clone", "alpha")
    package(tmp_path, "src/b", "beta")
    package(tmp_path, "install/alpha/share/alpha", "alpha")  # a committed install/ copy
    package(tmp_path, "build/x", "gamma")
    (tmp_path / "build" / "COLCON_IGNORE").write_text("")
    package(tmp_path, "src/b/test/nested", "nested")  # inside a package: not a package
    ws = discover(tmp_path)
    assert list(ws.packages) == ["alpha", "beta"]
    assert ws.packages["alpha"].root == tmp_path / "src" / "a_clone"
    assert ws.packages["beta"].depends == {"rviz2": 9}
    assert ws.packages["beta"].insert_line == 9
    assert any("found twice" in n for n in ws.notes)
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "old.urdf").write_text("<robot name='r'/>")  # outside every package
    assert discover(tmp_path).loose == (tmp_path / "docs" / "old.urdf",)
    assert has_packages(tmp_path) and not has_packages(tmp_path / "docs")


def test_symlinks_do_not_lead_out_of_dir(tmp_path: Path) -> None:
    outside = tmp_path / "outside"
    package(outside, "pkg", "outsider")
    (outside / "secret.yaml").write_text("controller_manager: {ros__parameters: {}}\n")
    ws_root = tmp_path / "ws"
    inner = package(ws_root, "src/inner", "inner")
    os.symlink(outside / "pkg", ws_root / "src" / "linked")  # a linked directory
    os.symlink(outside / "secret.yaml", inner / "config.yaml")  # a linked file
    ws = discover(ws_root)
    assert list(ws.packages) == ["inner"]
    with pytest.raises(Exception, match="outside"):
        ws.jail.read(inner / "config.yaml")


def test_a_malformed_package_xml_is_one_finding_with_its_line(tmp_path: Path) -> None:
    good = package(tmp_path, "src/good", "good")
    bad = tmp_path / "src" / "bad"
    bad.mkdir(parents=True)
    (bad / "package.xml").write_text("<package format='3'>\n  <name>bad\n</package>\n")
    found = findings(tmp_path)
    assert package_rules(found) == {"input-unusable"}
    (f,) = [f for f in found if f.rule == "input-unusable"]
    assert f.file == str(bad / "package.xml") and f.line == 3
    assert not [f for f in found if f.file == str(good / "package.xml")]
