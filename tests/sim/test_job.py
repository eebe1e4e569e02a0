"""What a simulate job keeps: the output rate's states and the final one, not every step."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from pytest import MonkeyPatch

from armcli.errors import InputError
from armcli.sim import job as simjob
from armcli.sim.options import SimOptions
from armcli.sim.plot import PLOT_POINTS
from armcli.sim.states import sample_states
from tests.helpers import DEFAULT_SPEC, spec_file

MSG = "{joint_names: [forearm_hand_joint], points: [{positions: [0.8], time_from_start: 1}]}"


def _job(duration: float, rate: float) -> simjob.SimJob:
    opts = SimOptions(message=MSG, duration=duration, rate=rate)
    return simjob.prepare(spec_file(DEFAULT_SPEC), opts)


def test_a_run_keeps_the_output_states_and_the_last() -> None:
    """7.05 s at 1 ms and 10 Hz: 71 samples (0 .. 7.0 s) and the final state at 7.05 s."""
    res = simjob.run(_job(7.05, 10.0))
    assert res.steps == 7050 and len(res.t) == 72
    np.testing.assert_array_equal(res.step, [*range(0, 7001, 100), 7050])
    cols = sample_states(res, 10.0)  # the file holds the rate's samples only
    assert len(cols["time"]) == 71 and cols["time"][-1] == 7.0
    assert res.stats.states == 7051  # the metrics saw every state


def test_a_plot_adds_an_even_spread_of_states() -> None:
    res = simjob.run(_job(7.05, 10.0), plot=True)
    assert PLOT_POINTS <= len(res.t) <= PLOT_POINTS + 72
    assert np.all(np.diff(res.step) > 0) and res.step[-1] == 7050


def test_a_held_arm_tracks_its_start_pose_built_as_an_object(monkeypatch: MonkeyPatch) -> None:
    """`hold=True` without a trajectory (the drive's arm): no YAML text is written and read."""
    from armcli.trajectory import message

    def refused(*args: object, **kwargs: object) -> None:
        raise AssertionError("the held start pose went through YAML text")

    monkeypatch.setattr(simjob, "loads_trajectory", refused)
    monkeypatch.setattr(message, "loads_trajectory", refused)
    job = simjob.prepare(spec_file(DEFAULT_SPEC), SimOptions(duration=0.1), hold=True)
    assert job.trajectory.source == simjob.HOLD
    assert job.trajectory.joint_names == job.robot.names
    np.testing.assert_array_equal(job.trajectory.positions, job.q0[None, :])  # the start pose
    np.testing.assert_array_equal(job.trajectory.times, [0.0])


def test_a_trajectory_handed_over_is_refused_where_a_file_would_be() -> None:
    file = spec_file(DEFAULT_SPEC)
    good = simjob.prepare(file, SimOptions(message=MSG, duration=1.5)).trajectory
    assert simjob.prepare(file, SimOptions(trajectory=good, duration=1.5)).trajectory is good
    unknown = replace(good, joint_names=("elbow",))
    with pytest.raises(InputError, match="unknown joint 'elbow'"):
        simjob.prepare(file, SimOptions(trajectory=unknown))
    beyond = replace(good, positions=good.positions + 10.0)  # past the joint's upper limit
    with pytest.raises(InputError, match="forearm_hand_joint leaves its range"):
        simjob.prepare(file, SimOptions(trajectory=beyond))
