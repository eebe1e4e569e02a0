"""armcli as a user gets it: the wheel in a fresh venv, every command run outside the checkout.

The editable install the rest of the suite uses hides packaging mistakes (data files not
shipped, a source file read at run time, a dependency missing from pyproject.toml), so
this module builds the wheel, installs it with `--no-index` from the wheelhouse of
exactly the runtime dependencies (see install_helpers), and drives the console script
from a temporary directory: --version, init, build, check, simulate, ros-package,
render, tree.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import zipfile
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import pytest
import yaml
from lxml import etree

from tests.install_helpers import ROOT, fresh_venv

pytestmark = pytest.mark.slow

COMMAND_TIMEOUT_S = 300
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PICK_END_S = 5.0  # specs/trajectories/pick.yaml: last point at sec 5
DEFAULT_TAIL_S = 2.0  # `armcli simulate --help`: duration defaults to the last point + 2 s
OUTPUT_RATE_HZ = 10.0  # specs/my_robot.yaml: joint_state_publisher update_rate
RATE_TOL_S = 1e-9  # sample times are k / rate, exact up to round-off
SPEC = ROOT / "specs" / "my_robot.yaml"


@dataclass(frozen=True)
class Installed:
    """The fresh installation and a project directory outside the checkout."""

    bin: Path
    wheel: Path
    project: Path
    env: dict[str, str]

    def run(self, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [str(self.bin / "armcli"), *args],
            cwd=cwd or self.project,
            env=self.env,
            capture_output=True,
            text=True,
            timeout=COMMAND_TIMEOUT_S,
            check=False,
        )


@pytest.fixture(scope="module")
def installed(
    tmp_path_factory: pytest.TempPathFactory, armcli_wheel: tuple[Path, Path]
) -> Installed:
    base = tmp_path_factory.mktemp("install")
    assert not base.resolve().is_relative_to(ROOT)  # really outside the checkout
    wheel, house = armcli_wheel
    bin_dir = fresh_venv(base / "venv", wheel, house)
    env = {
        "PATH": f"{bin_dir}{os.pathsep}/usr/bin{os.pathsep}/bin",  # the venv, not .venv
        "HOME": str(base / "home"),  # no user caches, no compiled rollout from `make native`
        "LANG": "C.UTF-8",
        "COLUMNS": "200",
    }
    project = base / "project"
    inst = Installed(bin_dir, wheel, project, env)
    r = inst.run("init", str(project), cwd=base)
    assert r.returncode == 0, r.stderr
    return inst


def _spec_links(spec: dict, *sections: str) -> set[str]:
    return {name for s in sections for name in spec[s]["links"]}


def test_version_names_the_installed_copy_and_libraries(installed: Installed) -> None:
    r = installed.run("--version")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    site = installed.bin.parent / "lib"
    # pyproject.toml is the single source; the dev venv's metadata was built from it
    assert lines[0].startswith(f"armcli {metadata.version('armcli')} ({site}")
    assert lines[1].startswith(("simulator engine: compiled", "simulator engine: unavailable"))
    # the wheelhouse holds exactly the versions installed in the development venv
    assert f"pin {metadata.version('pin')}" in lines
    assert f"xacro {metadata.version('xacro')}" in lines


def test_init_writes_the_shipped_example(installed: Installed) -> None:
    p = installed.project
    assert (p / "armcli.yaml").read_bytes() == SPEC.read_bytes()  # one source of truth
    names = sorted(f.name for f in (p / "trajectories").iterdir())
    assert names == sorted(f.name for f in (ROOT / "specs" / "trajectories").glob("*.yaml"))
    assert "armcli simulate --trajectory trajectories/pick.yaml" in (p / "README.md").read_text()
    again = installed.run("init", str(p))
    assert again.returncode == 2 and "already exists" in again.stderr


def test_without_a_spec_says_to_run_init(installed: Installed, tmp_path: Path) -> None:
    r = installed.run("build", cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "run `armcli init`" in r.stderr
    assert list(tmp_path.iterdir()) == []


def test_build_writes_urdfs_with_the_spec_links(installed: Installed) -> None:
    r = installed.run("build")
    assert r.returncode == 0, r.stderr
    spec = yaml.safe_load(SPEC.read_text())
    urdf = installed.project / "urdf"
    expected = {
        "my_robot.urdf": _spec_links(spec, "mobile_base", "arm"),
        "standalone_arm.urdf": _spec_links(spec, "arm") | {"world"},  # its massless root
    }
    for name, links in expected.items():
        root = etree.parse(str(urdf / name)).getroot()
        assert {e.get("name") for e in root.iter("link")} == links, name
    r = installed.run("build", "--check")
    assert r.returncode == 0, r.stderr


def test_check_is_clean(installed: Installed) -> None:
    r = installed.run("check", "--format", "json")
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["exit_code"] == 0
    assert {f["file"] for f in report["files"]} == {
        "armcli.yaml#my_robot.urdf",
        "armcli.yaml#standalone_arm.urdf",
    }


def test_simulate_writes_states(installed: Installed) -> None:
    r = installed.run(
        "simulate", "--trajectory", "trajectories/pick.yaml", "--output", "states.csv"
    )
    assert r.returncode == 0, r.stderr
    with (installed.project / "states.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    t = [float(row["time"]) for row in rows]
    assert t[-1] == pytest.approx(PICK_END_S + DEFAULT_TAIL_S, abs=RATE_TOL_S)
    assert len(t) == round((PICK_END_S + DEFAULT_TAIL_S) * OUTPUT_RATE_HZ) + 1
    assert "arm_base_forearm_joint.position" in rows[0]


def test_simulate_uses_the_compiled_engine(installed: Installed) -> None:
    with zipfile.ZipFile(installed.wheel) as zf:
        extensions = [n for n in zf.namelist() if n.endswith((".so", ".pyd"))]
    r = installed.run("simulate", "--trajectory", "trajectories/home.yaml")
    assert r.returncode == 0, r.stderr
    if not extensions:
        pytest.skip("the wheel holds no compiled extension (no C++ compiler)")
    assert "compiled engine" in r.stdout
    version = installed.run("--version").stdout.splitlines()
    assert version[1].startswith("simulator engine: compiled")


def test_ros_package(installed: Installed) -> None:
    r = installed.run("ros-package", "-o", "ros", "--samples", "200")
    assert r.returncode == 0, r.stderr
    for pkg in ("my_robot_description", "my_robot_bringup", "my_robot_moveit_config"):
        xml = etree.parse(str(installed.project / "ros" / pkg / "package.xml")).getroot()
        assert xml.findtext("name") == pkg


def test_render_writes_a_png(installed: Installed) -> None:
    r = installed.run("render", "--pose", "reach", "-o", "robot.png", "--size", "400x200")
    assert r.returncode == 0, r.stderr
    assert (installed.project / "robot.png").read_bytes()[:8] == PNG_MAGIC


def test_tree_lists_every_link(installed: Installed) -> None:
    r = installed.run("tree")
    assert r.returncode == 0, r.stderr
    for link in _spec_links(yaml.safe_load(SPEC.read_text()), "mobile_base", "arm"):
        assert link in r.stdout


def test_simulate_drives_the_whole_robot(installed: Installed) -> None:
    # the README's driving example, from the wheel: MuJoCo is a runtime dependency
    r = installed.run(
        "simulate", "--cmd-vel", "trajectories/drive.yaml", "--trajectory",
        "trajectories/pick.yaml", "--duration", "2", "-o", "run.mcap",
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    from rosbags.rosbag2 import Reader  # an MCAP reader independent of armcli's writer

    with Reader(installed.project / "run.mcap") as reader:
        topics = {c.topic for c in reader.connections}
    assert {"/odom", "/tf", "/joint_states", "/cmd_vel"} <= topics


def test_plan_then_simulate(installed: Installed) -> None:
    # the README's Plan & Execute loop, from the wheel: the compiled planner (libtoppra of
    # cmeel-toppra, a runtime dependency), or OMPL and toppra without a compiler
    with zipfile.ZipFile(installed.wheel) as zf:
        planner = [n for n in zf.namelist() if n.startswith("armcli/plan/_planner")]
    version = installed.run("--version").stdout.splitlines()
    assert version[2].startswith("planner: compiled" if planner else "planner: Python")
    r = installed.run("plan", "--from", "home", "--to", "reach", "-o", "planned.yaml")
    assert r.returncode == 0, r.stderr
    doc = yaml.safe_load((installed.project / "planned.yaml").read_text())
    assert doc["joint_names"] == ["arm_base_forearm_joint", "forearm_hand_joint"]
    r = installed.run("simulate", "--trajectory", "planned.yaml")
    assert r.returncode == 0, r.stderr
