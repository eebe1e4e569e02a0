"""Broken and hostile files through the real CLI: one clear line, right exit code, no output.

The corpus lives in tests/bad_inputs/ with its expectations in cases.yaml; a few
cases that would be wasteful to commit (huge files, a directory) are made here.
`check` reports findings on stdout (exit 1), so for those cases the runner also
asserts, from `--format json`, that an error finding of the expected rule names
the problem.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
from pathlib import Path

import pytest
import yaml

from tests.helpers import BAD_INPUTS, run_cli

HERE = BAD_INPUTS
CASES = yaml.safe_load((HERE / "cases.yaml").read_text())
PWNED = Path("/tmp/armcli-pwned")  # the hostile files try to create this
# A valid trajectory for the standalone arm's first joint, so that `simulate --urdf`
# fails on the URDF and not on the trajectory ({{ }}: str.format escapes).
TRAJECTORY_FOR_URDF = (
    "{{joint_names: [arm_base_forearm_joint], "
    "points: [{{positions: [0.1], time_from_start: {{sec: 1}}}}]}}"
)

COMMANDS = {
    "build": ["build", "{file}", "-o", "{out}/urdf"],
    "check": ["check", "{file}"],
    "check-json": ["check", "--format", "json", "{file}"],
    "simulate": [
        "simulate",
        "--trajectory",
        "{file}",
        "--output",
        "{out}/states.csv",
        "--plot",
        "{out}/plot.png",
    ],
    "simulate-message": ["simulate", "--message", "{text}", "--output", "{out}/states.csv"],
    "simulate-urdf": [
        "simulate",
        "--urdf",
        "{file}",
        "--message",
        TRAJECTORY_FOR_URDF,
        "--kp",
        "10",
        "--kd",
        "1",
        "--output",
        "{out}/states.csv",
    ],
    "ros-package": ["ros-package", "{file}", "-o", "{out}/ros"],
    "render": ["render", "{file}", "-o", "{out}/robot.png"],
    "tree": ["tree", "{file}", "-o", "{out}/tree.txt"],
    "check-trusted": ["check", "--trust-xacro", "{file}"],
    "tree-trusted": ["tree", "--trust-xacro", "{file}", "-o", "{out}/tree.txt"],
    "render-trusted": ["render", "--trust-xacro", "{file}", "-o", "{out}/robot.png"],
}


def assert_clean_failure(
    proc: subprocess.CompletedProcess[str], exit_code: int, message: str, out: Path
) -> None:
    assert proc.returncode == exit_code, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr + proc.stdout
    assert "internal error" not in proc.stderr
    first = proc.stderr.strip().splitlines()[0] if proc.stderr.strip() else ""
    assert re.search(message, first), f"{first!r} !~ {message!r}"
    assert list(out.iterdir()) == [], "output written despite the error"
    assert not PWNED.exists(), "hostile input executed code"


def assert_finding(stdout: str, rule: str, finding: str) -> None:
    """`check --format json` (exit 1) reported an error finding of `rule` matching `finding`."""
    doc = json.loads(stdout)
    messages = [
        f["message"]
        for file in doc["files"]
        for f in file["findings"]
        if f["rule"] == rule and f["severity"] == "error"
    ]
    assert any(re.search(finding, m) for m in messages), (rule, finding, messages)


def _param(case: dict) -> object:
    marks = [pytest.mark.xfail(reason=case["xfail"], strict=True)] if "xfail" in case else []
    return pytest.param(case, id=f"{case['file']}:{case['command']}", marks=marks)


@pytest.mark.parametrize("case", [_param(c) for c in CASES])
def test_corpus_case(case: dict, tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    path = HERE / case["file"]
    text = path.read_text(errors="replace") if case["command"] == "simulate-message" else ""
    args = [a.format(file=path, out=out, text=text) for a in COMMANDS[case["command"]]]
    proc = run_cli(args, root)
    assert_clean_failure(proc, case["exit"], case["message"], out)
    if "rule" in case:  # findings go to stdout; the stderr line only counts them
        assert_finding(proc.stdout, case["rule"], case.get("finding", ""))


def test_corpus_is_large_enough() -> None:
    assert len(CASES) >= 40
    assert {c["file"].split("/")[0] for c in CASES} >= {"spec", "urdf", "xacro"}


def test_huge_spec(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    huge = tmp_path / "huge.yaml"
    huge.write_text("name: x\n" + "# padding\n" * 200_000)
    proc = run_cli(["build", str(huge), "-o", str(out / "urdf")], root)
    assert_clean_failure(proc, 2, r"huge\.yaml: .*larger than", out)


def test_directory_instead_of_spec(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    proc = run_cli(["build", str(HERE / "spec"), "-o", str(out / "urdf")], root)
    assert_clean_failure(proc, 2, r"spec: is a directory", out)


def test_missing_spec(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    proc = run_cli(["build", str(tmp_path / "nope.yaml"), "-o", str(out / "urdf")], root)
    assert_clean_failure(proc, 2, r"nope\.yaml: YAML file not found", out)


def test_huge_urdf(tmp_path: Path, root: Path) -> None:
    from armcli.urdf.read import MAX_URDF_BYTES

    out = tmp_path / "out"
    out.mkdir()
    huge = tmp_path / "huge.urdf"
    huge.write_bytes(b'<robot name="x">' + b" " * MAX_URDF_BYTES + b"</robot>")
    for command in ("check", "tree", "render"):
        args = [a.format(file=huge, out=out) for a in COMMANDS[command]]
        assert_clean_failure(run_cli(args, root), 2, r"huge\.urdf: .*larger than", out)


def test_directory_instead_of_urdf(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    robot = tmp_path / "robot.urdf"
    robot.mkdir()
    for command in ("tree", "render"):
        args = [a.format(file=robot, out=out) for a in COMMANDS[command]]
        assert_clean_failure(run_cli(args, root), 2, r"robot\.urdf: is a directory", out)


@pytest.mark.parametrize("command", ["check", "tree", "build", "simulate", "simulate-urdf"])
def test_endless_device(command: str, tmp_path: Path, root: Path) -> None:
    """/dev/zero reports size 0 and never ends: refused by type before it is opened."""
    out = tmp_path / "out"
    out.mkdir()
    args = [a.format(file="/dev/zero", out=out) for a in COMMANDS[command]]
    assert_clean_failure(run_cli(args, root), 2, r"/dev/zero: is a character device", out)


@pytest.mark.parametrize(
    ("command", "name"),
    [
        ("check", "robot.urdf"),
        ("tree", "robot.urdf"),
        ("build", "spec.yaml"),
        ("simulate", "trajectory.yaml"),
        ("simulate-urdf", "robot.urdf"),
        ("check-trusted", "robot.xacro"),
    ],
)
def test_fifo_input_refused(command: str, name: str, tmp_path: Path, root: Path) -> None:
    """A FIFO blocked open() forever (no writer): refused before opening."""
    out = tmp_path / "out"
    out.mkdir()
    fifo = tmp_path / name
    os.mkfifo(fifo)
    args = [a.format(file=fifo, out=out) for a in COMMANDS[command]]
    message = rf"{re.escape(name)}: is a FIFO, expected a regular"
    assert_clean_failure(run_cli(args, root), 2, message, out)


def test_diverging_simulation_exits_1_without_output(tmp_path: Path, root: Path) -> None:
    # A URDF whose velocity limit (0.01 rad/s) the PD loop exceeds tenfold in one step:
    # the run must stop with the evidence, not write a misleading CSV or plot. The point is
    # the reference from t = 0 (a step, no segment to outrun the limit: a slower segment
    # would be refused before the run, sim.precheck), so the PD loop itself diverges.
    slow = tmp_path / "slow.urdf"
    slow.write_text(
        (root / "urdf" / "standalone_arm.urdf")
        .read_text()
        .replace('velocity="100"', 'velocity="0.01"')
    )
    out = tmp_path / "out"
    out.mkdir()
    message = (
        "{joint_names: [arm_base_forearm_joint, forearm_hand_joint], "
        "points: [{positions: [1.0, 1.0], time_from_start: 0}]}"
    )
    proc = run_cli(
        [
            "simulate",
            "--urdf",
            str(slow),
            "--joints",
            "arm_base_forearm_joint,forearm_hand_joint",
            "--kp",
            "50",
            "--kd",
            "5",
            "--message",
            message,
            "--output",
            str(out / "s.csv"),
            "--plot",
            str(out / "p.png"),
        ],
        root,
    )
    assert_clean_failure(
        proc,
        1,
        r"simulation diverged: velocity exceeded .* at t = [0-9.]+ s \(step \d+\) joint ",
        out,
    )
