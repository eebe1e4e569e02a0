"""`armcli simulate` end to end through the real command."""

from __future__ import annotations

import csv
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import ROOT, course_gains_spec, run_cli, run_main

TRAJ = ROOT / "specs" / "trajectories"
J1, J2 = "arm_base_forearm_joint", "forearm_hand_joint"
SEED = (
    "{header: {frame_id: arm_base_link}, joint_names: [arm_base_forearm_joint, "
    "forearm_hand_joint], points: [{positions: [0.0, 0.0]}]}"
)  # the course's `ros2 topic pub /set_joint_trajectory` payload, positions as a list
RATE = 10.0  # [Hz] joint_state_publisher update_rate in specs/my_robot.yaml
TRACK_TOL = 0.01  # [rad] final tracking: friction 0.05 / Kp 50 and gravity sag 0.6*9.81*0.15/50


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_main(["simulate", *args], capsys)


@pytest.fixture(autouse=True)
def _cwd(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)  # the default spec path is relative


def test_seed_message(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(["--message", SEED], capsys)
    assert code == 0, err
    assert J1 in out and J2 in out and "end effector" in out
    # The seed holds q = 0: tip in base_footprint at (base_length/4, 0, 0.1 + 0.2 + 0.02 + 0.6),
    # the same frame and numbers `check` and `view` report.
    assert "in base_footprint" in out
    assert "(0.1500, 0.0000, 0.9200) m" in out


COURSE_MESSAGE = (  # the course's `ros2 topic pub -1 /set_joint_trajectory ...` payload, verbatim
    "{header: {frame_id: arm_base_link}, joint_names: [arm_base_forearm_joint, "
    "forearm_hand_joint], points: [{positions: {0.0, 0.0}}]}"
)


def test_course_brace_form(capsys: pytest.CaptureFixture[str]) -> None:
    """The course's `{0.0, 0.0}` runs as the two zeros written, with one warning."""
    code, out, err = run(["--message", COURSE_MESSAGE], capsys)
    assert code == 0, err
    assert "(0.1500, 0.0000, 0.9200) m" in out  # q = 0, as test_seed_message
    assert err.count("warning:") == 1 and err.count("is a YAML mapping, not a list") == 1
    assert "--message points[0].positions" in err  # the flag, not the library's name
    assert "1 value(s) [0.0] for 2 joint(s)" in err and "[0.0, 0.0]" in err
    code, _, err = run(["--message", SEED.replace("[0.0, 0.0]", "{0.5, 0.3}")], capsys)
    assert code == 0, err
    assert err.count("is a YAML mapping, not a list") == 1 and "[0.5, 0.3]" in err
    code, _, err = run(["--message", SEED.replace("[0.0, 0.0]", "{0.5}")], capsys)
    assert code == 2 and "1 value(s) for 2 joint(s)" in err


@pytest.mark.parametrize(  # drive.yaml holds /cmd_vel commands: tests/cli/test_drive.py
    "name", sorted(p.name for p in TRAJ.glob("*.yaml") if "\ncommands:" not in p.read_text())
)
def test_example_trajectories_csv(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out_csv = tmp_path / "states.csv"
    code, _, err = run(["--trajectory", str(TRAJ / name), "--output", str(out_csv)], capsys)
    assert code == 0, err
    with out_csv.open() as fh:
        rows = list(csv.reader(fh))
    header, body = rows[0], np.array(rows[1:], dtype=float)
    cols = [f"{j}.{f}" for j in (J1, J2) for f in ("position", "velocity", "effort", "reference")]
    # the robot stands on its wheels: the zero-moment point's columns follow (sim.tipping)
    assert header == ["time", *cols, "zmp.x", "zmp.y", "zmp.margin", "zmp.margin_base"]
    assert np.all(body[:, 11:] > 0.02)  # the seed never comes near its polygon's edge
    np.testing.assert_allclose(np.diff(body[:, 0]), 1.0 / RATE, atol=1e-9)
    q = body[:, [1, 5]]
    assert np.all(q >= 0.0) and np.all(q <= math.pi / 2)  # the seed's joint limits
    final_ref = body[-1, [4, 8]]
    np.testing.assert_allclose(q[-1], final_ref, atol=TRACK_TOL)


def test_json_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out_json, png = tmp_path / "s.json", tmp_path / "t.png"
    args = ["-t", str(TRAJ / "pick.yaml"), "-o", str(out_json), "--plot", str(png), "--rate", "20"]
    code, out, err = run(args, capsys)
    assert code == 0, err
    data = json.loads(out_json.read_text())
    assert next(iter(data)) == "time" and f"{J2}.reference" in data
    # pick.yaml ends at 5 s, +2 s default settle time, sampled at 20 Hz
    assert len(data["time"]) == int(7.0 * 20) + 1
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    assert f"wrote {png}" in out


def test_unknown_joint_one_clear_line_no_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out_csv = tmp_path / "s.csv"
    msg = "{joint_names: [elbow], points: [{positions: [0.1]}]}"
    code, _out, err = run(["--message", msg, "-o", str(out_csv)], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1
    assert "--message" in lines[0] and "joint_names[0]" in lines[0] and J1 in lines[0]
    assert not out_csv.exists()


def test_limits_error_or_clamp(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "far.yaml"
    bad.write_text(f"joint_names: [{J1}]\npoints:\n  - positions: [2.0]\n")
    code, _, err = run(["-t", str(bad)], capsys)
    assert code == 2 and f"{bad}:3" in err and "points[0].positions[0]" in err
    code, _out, err = run(["-t", str(bad), "--clamp"], capsys)
    assert code == 0 and "warning" in err and "clamped" in err


def test_rk4_at_default_dt_is_refused_with_advice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = str(course_gains_spec(tmp_path))  # Kd 5: dt (Kd + damping) lambda_max = 2.8 at 1 ms
    code, _, err = run([spec, "--message", SEED, "--integrator", "rk4"], capsys)
    assert code == 2 and "stable for dt <=" in err and "default euler integrator" in err
    # dt and gains came from the spec: the error names its fields, not an option
    assert f"{spec} control.dt, control.gains: " in err and "--dt" not in err
    code, _, err = run([spec, "--message", SEED, "--integrator", "rk4", "--dt", "0.0005"], capsys)
    assert code == 0, err


def test_any_urdf_with_locked_joints(built_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = built_dir / "standalone_arm.urdf"
    msg = "{joint_names: [forearm_hand_joint], points: [{positions: [0.7], time_from_start: 1}]}"
    args = ["--urdf", str(urdf), "--joints", J2, "--kp", "50", "--kd", "5", "-m", msg]
    code, out, err = run(args, capsys)
    assert code == 0, err
    assert J2 in out and J1 not in out


def test_bad_output_extension_fails_before_running(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(["--message", SEED, "-o", str(tmp_path / "s.txt")], capsys)
    assert code == 2 and "--output" in err
    assert not (tmp_path / "s.txt").exists()


def test_integral_gain_is_refused_not_ignored(tmp_path: Path) -> None:
    """The simulator is PD: a spec ki > 0 is an error naming the field, unless --kp/--kd given."""
    text = (ROOT / "specs" / "my_robot.yaml").read_text()
    spec = tmp_path / "ki.yaml"
    spec.write_text(re.sub(r"(kd: [0-9.]+)\}", r"\1, ki: 0.5}", text, count=1))
    traj = str(ROOT / "specs" / "trajectories" / "pick.yaml")
    res = run_cli(["simulate", spec, "-t", traj, "--duration", "0.5"])
    assert res.returncode == 2
    assert "control.gains." in res.stderr and ".ki" in res.stderr and "PD" in res.stderr
    ok = run_cli(["simulate", spec, "-t", traj, "--duration", "0.5", "--kp", "50", "--kd", "5"])
    assert ok.returncode == 0, ok.stderr


def test_engine_is_reported_and_a_missing_one_is_one_error(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from armcli.sim import native

    code, out, _ = run(["--trajectory", str(TRAJ / "pick.yaml")], capsys)
    assert code == 0 and "compiled engine" in out
    monkeypatch.setenv("ARMCLI_NO_NATIVE", "1")
    monkeypatch.setattr(native.ROLLOUT, "_loaded", None)  # asked again
    code, _, err = run(["--trajectory", str(TRAJ / "pick.yaml")], capsys)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "simulator is unavailable" in lines[0]


PENDULUM = ROOT / "tests" / "fixtures" / "stability" / "pendulum_1cm.urdf"
HANG = "{joint_names: [swing_joint], points: [{positions: [0.0], time_from_start: 1}]}"


def test_the_issues_1cm_pendulum_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 24: accepted before, it banged between the stops at 44 rad/s and exited 0.
    Hanging, gravity's stiffness m g l = 9.81e-3 N·m/rad against I = 1.016e-5 kg·m²
    needs dt < 2 sqrt(I / (k + Kp)) = 0.0613 s."""
    args = ["--urdf", str(PENDULUM), "--kp", "0.001", "--kd", "0", "--dt", "0.1", "-m", HANG]
    code, _, err = run(args, capsys)
    assert code == 2
    assert "--dt, --kp, --kd: armcli simulate (damping implicit) diverges" in err
    assert "gravity's stiffness up to 0.00981" in err and "stable for dt <= 0.0613 s" in err
    assert "e.g. dt = 0.055 s" in err
    code, _, err = run([*args[:-4], "--dt", "0.055", "-m", HANG], capsys)
    assert code == 0, err


def test_ignore_lets_a_true_finding_simulate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 19: students' arms with a true inertia-exceeds-geometry finding."""
    arm = (ROOT / "urdf" / "standalone_arm.urdf").read_text()
    # 20x the forearm's ixx and iyy: more than any mass inside its cylinder can have
    heavy = arm.replace('ixx="0.00228" ixy="0" ixz="0" iyy="0.00228"',
                        'ixx="0.0456" ixy="0" ixz="0" iyy="0.0456"', 1)  # fmt: skip
    assert heavy != arm
    urdf = tmp_path / "student.urdf"
    urdf.write_text(heavy)
    msg = "{joint_names: [forearm_hand_joint], points: [{positions: [0.3], time_from_start: 1}]}"
    args = ["--urdf", str(urdf), "--kp", "50", "--kd", "5", "-m", msg]
    code, _, err = run(args, capsys)
    assert code == 2 and "[inertia-exceeds-geometry]" in err
    assert "simulate it anyway with --ignore inertia-exceeds-geometry" in err
    code, out, err = run([*args, "--ignore", "inertia-exceeds-geometry"], capsys)
    assert code == 0, err
    assert J2 in out
    code, _, err = run([*args, "--ignore", "no-such-rule"], capsys)
    assert code == 2 and "--ignore" in err and "no-such-rule" in err


HEAVY = {"pinocchio", "scipy", "matplotlib", "mujoco", "yourdfpy", "trimesh", "xacro",
         "armcli.check.gate", "armcli.spec.model", "numpy.ma"}  # fmt: skip


def _modules_after(args: list[str]) -> set[str]:
    """The modules a fresh interpreter holds after `armcli ARGS` (run in it)."""
    code = (
        "import sys\nfrom armcli.cli import main\n"
        f"try:\n    main({args!r})\nexcept SystemExit as e:\n    assert e.code in (0, None), e\n"
        "print('@@modules@@', *sys.modules)\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       check=False, cwd=ROOT)  # fmt: skip
    assert r.returncode == 0, r.stderr
    return set(r.stdout.split("@@modules@@")[-1].split())


def test_help_imports_nothing_heavy() -> None:
    """`simulate --help` is instant: no dynamics, plotting, check rules or spec models."""
    assert not HEAVY & _modules_after(["simulate", "--help"])


def test_simulating_a_urdf_needs_no_spec_layers() -> None:
    """A --urdf run reads no spec: the pydantic spec models (~0.3 s) are not imported."""
    msg = "{joint_names: [forearm_hand_joint], points: [{positions: [0.3], time_from_start: 0.1}]}"
    loaded = _modules_after(["simulate", "--urdf", "urdf/standalone_arm.urdf", "--kp", "50",
                             "--kd", "5", "-m", msg, "--duration", "0.2"])  # fmt: skip
    assert "pinocchio" in loaded and "armcli.spec.model" not in loaded
    assert not {"matplotlib", "scipy", "mujoco", "numpy.ma"} & loaded


def test_a_wheel_joint_is_not_an_arm_joint(capsys: pytest.CaptureFixture[str]) -> None:
    message = SEED.replace("arm_base_forearm_joint", "base_left_wheel_joint")
    code, _, err = run(["--message", message], capsys)
    assert code == 2 and "is a wheel joint of the mobile base, not an arm joint" in err


def test_nothing_to_simulate_names_every_way_in(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_main(["simulate", "specs/my_robot.yaml"], capsys)
    assert code == 2
    assert "--trajectory" in err and "--message" in err and "--cmd-vel" in err
