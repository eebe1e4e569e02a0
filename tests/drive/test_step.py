"""The drive's compiled steps against its Python steps: the same run, bit for bit.

drive.step runs the steps between two plugin updates in C++ (armcli.sim._drivestep)
or, without the extension, in Python. Both must be the same arithmetic in the same order:
the reference is the Python loop (the one the drive ran before the compiled one existed),
on a run that exercises every term: the base driving and turning (rotor speeds, clutch
torques), the arm moving under gravity compensation (g(q) of the fixed-base arm), the
reference held by a pilot, a mimic-free course robot and its recorded sensors.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.drive import job as drive
from armcli.drive import step as drivestep
from armcli.sim.options import SimOptions
from tests.helpers import DEFAULT_SPEC, spec_file

pytest.importorskip("mujoco")

MOVES = (
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 1.0}\n"
    " - {positions: [0.9, 1.2], time_from_start: 2.0}\n"
)
DRIVE = (
    "commands:\n  - {linear: {x: 0.2}, time_from_start: 0.3}\n"
    "  - {angular: {z: 0.6}, time_from_start: 1.2}\n"
    "  - {linear: {x: -0.1}, angular: {z: -0.3}, time_from_start: 2.0}\n"
)


class HoldingPilot:
    """Follows the file's commands, holds the arm's reference for HOLD steps, sums speeds."""

    HOLD = 300

    def __init__(self, job: drive.DriveJob) -> None:
        self.job = job
        self.speed_sum = 0.0
        self.seen_steps: list[int] = []

    def command(self, t: float, data: object) -> tuple[float, float]:
        lin, ang = self.job.cmd.at(np.array([t]))
        return float(lin[0]), float(ang[0])

    def arm_steps(self, k0: int, k1: int) -> np.ndarray:
        return np.maximum(np.arange(k0, k1) - self.HOLD, 0)

    def observe(self, k0: int, seen: np.ndarray) -> None:
        self.seen_steps.extend(range(k0, k0 + len(seen)))
        self.speed_sum += float(np.sum(seen[:, 7:9]))


def _runs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, pilot: bool) -> list[drive.DriveRun]:
    cmd = tmp_path / "drive.yaml"
    cmd.write_text(DRIVE)
    opts = SimOptions(message=MOVES, duration=2.5, gravity_comp=True)
    job = drive.prepare(spec_file(DEFAULT_SPEC), opts, cmd)
    out = []
    for compiled in (True, False):
        if not compiled:
            monkeypatch.setattr(drivestep, "load", lambda: None)
        out.append(drive.run(job, pilot=HoldingPilot(job) if pilot else None))
    return out


@pytest.mark.parametrize("pilot", [False, True], ids=["open-loop", "pilot"])
def test_the_compiled_steps_are_the_python_steps_bit_for_bit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, pilot: bool
) -> None:
    if drivestep.load() is None:
        pytest.skip("armcli.sim._drivestep is not built")
    compiled, python = _runs(tmp_path, monkeypatch, pilot)
    assert np.array_equal(compiled.sensors, python.sensors)  # every state, every sensor
    assert np.array_equal(compiled.q_ref, python.q_ref)
    assert np.array_equal(compiled.wheel_command, python.wheel_command)
    assert np.any(compiled.wheel_command != 0.0)  # the run drives
    L = compiled.job.model.layout
    assert np.ptp(compiled.sensors[:, L.arm_pos], axis=0).min() > 0.1  # and moves the arm


def test_a_pilot_observes_every_step_once_from_the_state_it_started(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cmd = tmp_path / "drive.yaml"
    cmd.write_text(DRIVE)
    job = drive.prepare(spec_file(DEFAULT_SPEC), SimOptions(duration=1.0), cmd)
    pilot = HoldingPilot(job)
    run = drive.run(job, pilot=pilot)
    assert pilot.seen_steps == list(range(run.steps))
    # seen[k]'s wheel speeds are state k's, the ones the jointvel sensors record for state k
    wheels = run.sensors[:-1, job.model.layout.wheel_vel]
    assert pilot.speed_sum == pytest.approx(float(np.sum(wheels)), rel=1e-12)
