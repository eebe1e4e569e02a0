"""The compiled engine as a module: batches on threads, engine choice and its notice."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError
from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.sim.reference import build_reference
from armcli.sim.simulate import Arm, SimConfig, arm_from_model, params_of, simulate
from armcli.sim.trajectory import loads_trajectory
from armcli.urdf.pinocchio import load_model
from tests.sim.engines import require_native

TRAJ = (
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 0.5}\n"
    " - {positions: [0.9, 1.2], time_from_start: 1.0}\n"
)


@pytest.fixture(scope="module")
def arm(built_dir: Path) -> Arm:
    return arm_from_model(load_model(built_dir / "standalone_arm.urdf").model)


def _ref(arm: Arm, steps: int, dt: float) -> np.ndarray:
    tr = loads_trajectory(TRAJ, dict.fromkeys(arm.joint_names, (0.0, math.pi / 2)))
    q, v = build_reference(tr, arm.joint_names, np.zeros(2)).sample(np.arange(steps + 1) * dt)
    return np.ascontiguousarray(np.hstack([q, v]))


def test_batch_on_threads_equals_one_by_one(arm: Arm) -> None:
    """Many gain sets and two models (one with a weaker hand) in one threaded batch."""
    mod = require_native()
    weak = replace(arm, effort=np.array([3.0, 0.5]))
    ref = _ref(arm, 1500, 1e-3)
    jobs = []
    for k, a in enumerate([arm, weak] * 6):
        cfg = SimConfig(np.full(2, 20.0 + 10 * k), np.full(2, 1.0 + k), dt=1e-3)
        plant = ro.Plant(a.model, params_of(a, cfg), k % 2 == 0, 1e-3, "euler", math.inf)
        jobs.append(native.Job(plant, np.zeros(2), np.zeros(2), ref))
    together = native.rollout_batch(mod, jobs, threads=4)
    for job, r in zip(jobs, together, strict=True):
        alone = ro.rollout_python(job.plant, job.q0, job.v0, job.ref)
        # the same arithmetic on any thread: equal to the Python reference to round-off
        np.testing.assert_allclose(r.q, alone.q, atol=1e-12, rtol=0)
        np.testing.assert_array_equal(r.flags, alone.flags)
    assert len({float(r.q[-1, 0]) for r in together}) == len(jobs)  # really different runs


def test_missing_extension_is_a_notice_not_a_crash(
    arm: Arm, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ARMCLI_NO_NATIVE", "1")
    monkeypatch.setattr(native, "_state", {})
    tr = loads_trajectory(TRAJ, dict.fromkeys(arm.joint_names, (0.0, math.pi / 2)))
    ref = build_reference(tr, arm.joint_names, np.zeros(2))
    cfg = SimConfig(np.full(2, 50.0), np.full(2, 5.0), dt=1e-3)
    res = simulate(arm, ref, np.zeros(2), 0.2, cfg)
    assert res.backend == "python" and res.notice is not None and "\n" not in res.notice
    with pytest.raises(InputError, match="compiled simulator is unavailable"):
        simulate(arm, ref, np.zeros(2), 0.2, replace(cfg, backend="native"))


def test_model_arrays_keep_unaligned_axes() -> None:
    """The generic JointModel has no axis; the flat model must carry the concrete one."""
    import pinocchio as pin

    model = pin.Model()
    axis = np.array([0.36, 0.48, 0.8])  # unit, not along x, y or z
    jid = model.addJoint(0, pin.JointModelRevoluteUnaligned(axis), pin.SE3.Identity(), "r")
    pin_axis = np.array([0.0, 0.6, -0.8])
    model.addJoint(jid, pin.JointModelPrismaticUnaligned(pin_axis), pin.SE3.Identity(), "p")
    arrays = native.model_arrays(model)
    np.testing.assert_array_equal(arrays["axis"], [axis, pin_axis])
    assert arrays["jtype"].tolist() == [3, 7]


def test_simulate_batch_equals_simulate_run_by_run() -> None:
    """The batch entry point (used by `armcli tune`) gives each run's `simulate` result exactly,
    diverged runs included."""
    from armcli.errors import SimulationError
    from armcli.sim.job import load_arm
    from armcli.sim.reference import build_reference
    from armcli.sim.simulate import Run, SimConfig, simulate, simulate_batch
    from armcli.sim.trajectory import loads_trajectory
    from armcli.spec.load import load_spec
    from tests.helpers import DEFAULT_SPEC

    arm = load_arm(load_spec(DEFAULT_SPEC), None, None)
    limits = {
        n: (float(lo), float(hi))
        for n, lo, hi in zip(arm.joint_names, arm.lower, arm.upper, strict=True)
    }
    text = (
        "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\n"
        "points: [{positions: [0.8, 0.4]}, {positions: [0.2, 1.2]}]"
    )
    traj = loads_trajectory(text, limits)
    q0 = np.zeros(2)
    ref = build_reference(traj, arm.joint_names, q0)
    runs = [
        Run(arm, ref, q0, 3.0, SimConfig(kp=np.full(2, kp), kd=np.full(2, kd), integrator=integ))
        for kp, kd, integ in [
            (50, 5, "euler"),
            (200, 2, "euler"),
            (50, 5, "rk4"),
            (50, -5, "euler"),
        ]
    ]
    batch = simulate_batch(runs)
    # negative Kd pumps energy in: that run diverges
    assert sum(isinstance(r, SimulationError) for r in batch) == 1
    for run, got in zip(runs, batch, strict=True):
        try:
            want = simulate(run.arm, run.reference, run.q0, run.duration, run.cfg)
        except SimulationError as exc:
            assert isinstance(got, SimulationError) and str(got) == str(exc)
            continue
        assert not isinstance(got, SimulationError)
        np.testing.assert_array_equal(got.q, want.q)
        np.testing.assert_array_equal(got.tau, want.tau)
