"""Shared test helpers: repository paths, and mutation strategies for fuzzing loaders.

Mutations start from a valid document and change one place at a time (replace
a value with a hostile one, drop a key, add an unknown key), so the fuzzer
spends its time just past the validator's edge rather than on random bytes.
"""

from __future__ import annotations

import copy
import math
import os
import re
import subprocess
import sys
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest
from hypothesis import strategies as st

if TYPE_CHECKING:
    from armcli.robot.model import Robot
    from armcli.urdf.source import RobotFile

ROOT = Path(__file__).resolve().parents[1]  # the repository checkout
SPECS = ROOT / "specs"
DEFAULT_SPEC = SPECS / "my_robot.yaml"
FIXTURES = ROOT / "tests" / "fixtures"
BAD_INPUTS = ROOT / "tests" / "bad_inputs"
# The course's PD gains (the MoveIt tutorial's Kp 50, Kd 5): stable in armcli simulate's
# loop, not in an explicit torque loop at 1 ms. The example spec keeps Kp and lowers Kd.
COURSE_GAINS = {"arm_base_forearm_joint": (50.0, 5.0), "forearm_hand_joint": (50.0, 5.0)}


def gains_text(text: str, gains: dict[str, tuple[float, float]]) -> str:
    """Spec YAML text with `joint: {kp: .., kd: ..}` lines set to `gains` (one line each)."""
    for joint, (kp, kd) in gains.items():
        line = rf"\g<1>{{kp: {kp:g}, kd: {kd:g}}}"
        text, n = re.subn(rf"(\n    {joint}: )\{{kp: [^}}\n]*\}}", line, text)
        assert n == 1, joint
    return text


def load_robot(path: Path, *, floating: bool = False, strict: bool = True) -> Robot:
    """The robot of a URDF file as armcli loads it: the strict reader, then `Robot.load`."""
    from armcli.robot.model import Robot
    from armcli.urdf.read import read_urdf

    return Robot.load(read_urdf(path), floating=floating, strict=strict)


def spec_file(path: Path) -> RobotFile:
    """A spec file's robot file, as a command reads it (the library's entry points take it)."""
    from armcli.urdf.source import read_robot

    return read_robot(path)


def course_gains_spec(directory: Path, name: str = "my_robot.yaml") -> Path:
    """specs/my_robot.yaml with the course's gains (COURSE_GAINS), written into `directory`."""
    path = directory / name
    path.write_text(gains_text(DEFAULT_SPEC.read_text(), COURSE_GAINS))
    return path


CLI_TIME_LIMIT_S = 120.0  # one CLI run on a loaded 2-core machine


def run_cli(
    args: Sequence[str | Path],
    cwd: Path | None = None,
    env: Mapping[str, str] | None = None,
    *,
    preexec_fn: Callable[[], Any] | None = None,
    unset: Sequence[str] = (),
    timeout: float = CLI_TIME_LIMIT_S,
) -> subprocess.CompletedProcess[str]:
    """`python -m armcli.cli ARGS` as its own process: exit code, stdout, stderr, files.

    `env` adds to (or overrides) this process's environment, without ARMCLI_DEBUG (errors
    stay one line) and the variables in `unset`. For in-process calls that only need the
    output, tests call `armcli.cli.main` directly instead.
    """
    drop = {"ARMCLI_DEBUG", *unset}
    return subprocess.run(
        [sys.executable, "-m", "armcli.cli", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
        cwd=cwd,
        env={**{k: v for k, v in os.environ.items() if k not in drop}, **(env or {})},
        preexec_fn=preexec_fn,
    )


def run_main(args: Sequence[object], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """`armcli ARGS` in this process (`armcli.cli.main`): exit code, stdout, stderr.

    Each argument is passed as its `str()`: paths and numbers as they are.
    """
    from armcli.cli import main

    try:
        main([str(a) for a in args])
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err


HOSTILE_SCALARS: st.SearchStrategy[Any] = st.one_of(
    st.sampled_from(
        [
            math.nan,
            math.inf,
            -math.inf,
            0,
            -1,
            -1e300,
            1e300,
            "",
            "pi/0",
            "__import__('os')",
            "pi/2",
            True,
            None,
            "../../etc/passwd",
            "\x00",
            "0" * 200,
            [],
            {},
        ]
    ),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.text(max_size=20),
    st.lists(st.floats(allow_nan=False), max_size=4),
)


def paths(data: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every path to a node of nested dicts/lists."""
    out = [prefix]
    if isinstance(data, dict):
        for k, v in data.items():
            out += paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out += paths(v, (*prefix, i))
    return out


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    node = data
    for p in path[:-1]:
        node = node[p]
    return node


@st.composite
def mutated(draw: st.DrawFn, base: Any, max_mutations: int = 3) -> Any:
    """`base` with 1..max_mutations structured changes."""
    doc = copy.deepcopy(base)
    for _ in range(draw(st.integers(1, max_mutations))):
        candidates = [p for p in paths(doc) if p]
        if not candidates:
            break
        path = draw(st.sampled_from(candidates))
        parent = _parent(doc, path)
        action = draw(st.sampled_from(["replace", "delete", "add", "wrap"]))
        if action == "replace":
            parent[path[-1]] = draw(HOSTILE_SCALARS)
        elif action == "delete":
            if isinstance(parent, dict):
                del parent[path[-1]]
            else:
                parent.pop(path[-1])
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=8))] = draw(HOSTILE_SCALARS)
        elif action == "wrap":
            parent[path[-1]] = [parent[path[-1]]]
    return doc


# A ROS 2 workspace fixture (tests/fixtures/ros_ws/src): two packages whose clone
# directories are not named like the packages, built into an ament install prefix the
# way `colcon build --symlink-install --merge-install` leaves it.
ROS_WS_SRC = FIXTURES / "ros_ws" / "src"
ARM_PACKAGE, GRIPPER_PACKAGE = "demo_arm_description", "demo_gripper_description"
DEMO_ARM = ROS_WS_SRC / "arm_clone" / "urdf" / "demo_arm.urdf.xacro"
AMENT_MARKERS = Path("share", "ament_index", "resource_index", "packages")


def symlink_install(src: Path, prefix: Path) -> Path:
    """`prefix`/share/NAME for each package under `src`: real directories, one symlink per
    file into the source (as ament_cmake's symlink install), plus the ament index marker."""
    import re

    for xml in sorted(src.glob("*/package.xml")):
        name = re.search(r"<name>([^<]+)</name>", xml.read_text())
        assert name is not None, xml
        share = prefix / "share" / name.group(1)
        for f in sorted(p for p in xml.parent.rglob("*") if p.is_file()):
            target = share / f.relative_to(xml.parent)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.symlink_to(f)
        (prefix / AMENT_MARKERS).mkdir(parents=True, exist_ok=True)
        (prefix / AMENT_MARKERS / name.group(1)).touch()
    return prefix


def ament_index_shim() -> Any:
    """A stand-in for ROS 2's `ament_index_python` (not on PyPI) so that xacro itself can
    resolve `$(find)` as a sourced workspace does: `<prefix>/share/NAME` of the first
    AMENT_PREFIX_PATH prefix whose ament index registers NAME. Install it with
    `monkeypatch.setitem(sys.modules, ...)` for both returned modules."""
    import os
    import types

    class PackageNotFoundError(KeyError):
        pass

    def get_package_share_directory(name: str, print_warning: bool = True) -> str:
        for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
            if prefix and (Path(prefix) / AMENT_MARKERS / name).is_file():
                return os.path.join(prefix, "share", name)
        raise PackageNotFoundError(name)

    top = types.ModuleType("ament_index_python")
    packages = types.ModuleType("ament_index_python.packages")
    packages.get_package_share_directory = get_package_share_directory  # type: ignore[attr-defined]
    packages.PackageNotFoundError = PackageNotFoundError  # type: ignore[attr-defined]
    top.packages = packages  # type: ignore[attr-defined]
    return top, packages
