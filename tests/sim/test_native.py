"""The compiled engine as a module: the exact model it receives, batches on threads, chunking
and recording that change nothing, running statistics, and refusing a missing or stale build."""

from __future__ import annotations

import math
from pathlib import Path
from typing import cast

import numpy as np
import pinocchio as pin
import pytest

from armcli.errors import InputError, SimulationError
from armcli.robot.model import Robot
from armcli.sim import native
from armcli.sim import rollout as ro
from armcli.sim.options import Integrator
from armcli.sim.simulate import (
    SETTLE_TOL,
    Run,
    SimConfig,
    plant_of,
    simulate,
    simulate_batch,
    simulated,
)
from armcli.trajectory.message import loads_trajectory
from armcli.trajectory.reference import build_reference
from tests.helpers import load_robot
from tests.sim.engines import require_native, run_held
from tests.sim.test_rollout import TILTED_URDF

ERD = (
    Path(pin.__file__).resolve().parents[4] / "share" / "example-robot-data" / "robots"
)  # example-robot-data's URDFs, shipped in the dev extra under cmeel.prefix
TRAJ = (
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 0.5}\n"
    " - {positions: [0.9, 1.2], time_from_start: 1.0}\n"
)


@pytest.fixture(scope="module")
def arm(built_dir: Path) -> Robot:
    return simulated(load_robot(built_dir / "standalone_arm.urdf"))


def _reference(arm: Robot):
    tr = loads_trajectory(TRAJ, dict.fromkeys(arm.names, (0.0, math.pi / 2)))
    return build_reference(tr, arm.names, np.zeros(2))


def _erd_models() -> list[pin.Model]:
    models = []
    for path in sorted(ERD.glob("**/*.urdf")) if ERD.is_dir() else []:
        try:
            models.append(pin.buildModelFromUrdf(str(path)))
        except (RuntimeError, ValueError):
            continue  # e.g. ur3.urdf has no robot name
    return models


def _free_step_equals_python_aba(model: pin.Model) -> bool:
    """One Euler step of the free arm from a random state, against Pinocchio in Python:
    v1 = v0 + dt a, q1 = q0 + dt v1 with a = ABA(q0, v0, 0), bit for bit. False when
    Python's ABA is not finite (massless chains: a singular mass matrix)."""
    simulable = [model.names[j] for j in range(1, model.njoints) if model.joints[j].nv == 1]
    arm = simulated(Robot(model), simulable)
    n, dt = arm.model.nv, 1e-3
    wide = arm.with_limits(lower=np.full(n, -1e9), upper=np.full(n, 1e9), damping=np.zeros(n),
                   friction=np.zeros(n), velocity=np.full(n, 1e9))  # fmt: skip
    rng = np.random.default_rng(n)
    q0, v0 = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    a = pin.aba(wide.model, wide.model.createData(), wide.q(q0), v0,
                np.zeros(n), pin.Convention.WORLD)  # fmt: skip
    if not np.all(np.isfinite(a)):
        return False
    r = run_held(plant_of(wide, SimConfig(np.zeros(n), np.zeros(n), dt=dt)), q0, v0, 1).trace
    v1 = v0 + dt * a
    np.testing.assert_array_equal(r.v[1], v1)
    np.testing.assert_array_equal(r.q[1], q0 + dt * v1)
    return True


def test_the_engine_receives_the_model_exactly() -> None:
    """Pinocchio's own serialisation hands the model over: the first step equals Python's
    ABA exactly (rebuilding it with appendBodyToJoint moved centres of mass by an ulp,
    2.3e-13 on some arms). Unaligned axes, prismatic and continuous joints included."""
    require_native()
    models = [pin.buildModelFromXML(TILTED_URDF), *_erd_models()]
    compared = sum(_free_step_equals_python_aba(model) for model in models)
    # example-robot-data 4.x: 60+ URDFs, a few with massless chains
    assert compared >= 40 or (not ERD.is_dir() and compared == 1)


def test_chunking_and_recording_change_nothing(arm: Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    """The run continues across chunks (friction's warm start included) and keeping a
    subset of the states keeps exactly those rows."""
    require_native()
    cfg = SimConfig(np.full(2, 50.0), np.full(2, 2.0), dt=1e-3, gravity_comp=True)
    ref = _reference(arm)
    whole = simulate(arm, ref, np.zeros(2), 1.5, cfg)
    monkeypatch.setattr(ro, "CHUNK_STEPS", 7)
    keep = np.array([0, 3, 500, 501, 1499, 1500])
    part = simulate(arm, ref, np.zeros(2), 1.5, cfg, record=keep)
    for name in ("q", "v", "q_ref", "v_ref", "tau", "saturated", "stop_active"):
        np.testing.assert_array_equal(getattr(part, name), getattr(whole, name)[keep])
    for f in part.stats.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(part.stats, f), getattr(whole.stats, f))


def test_running_statistics_equal_the_full_trace(arm: Robot) -> None:
    """Statistics the engine accumulates step by step, against numpy on every state."""
    require_native()
    weak = arm.with_limits(effort=np.array([3.0, 1.0]))  # saturates; the stops are hit
    cfg = SimConfig(np.full(2, 50.0), np.full(2, 2.0), dt=5e-4)
    res = simulate(weak, _reference(arm), np.zeros(2), 2.0, cfg)
    e = res.q - res.q_ref
    st = res.stats
    assert st.states == res.steps + 1 == len(res.t)
    np.testing.assert_allclose(st.sum_e2, np.sum(e**2, axis=0), rtol=1e-12)
    np.testing.assert_array_equal(st.max_e, np.max(np.abs(e), axis=0))
    np.testing.assert_array_equal(st.last_e, e[-1])
    outside = [np.nonzero(np.abs(e[:, i]) > SETTLE_TOL)[0] for i in range(2)]
    np.testing.assert_array_equal(st.last_out, [o[-1] if o.size else -1 for o in outside])
    steps_sat, steps_stop = res.saturated[:-1], res.stop_active[:-1]  # one row per step
    np.testing.assert_array_equal(st.saturated_steps, steps_sat.sum(axis=0))
    rises = steps_stop[0].astype(int) + (steps_stop[1:] & ~steps_stop[:-1]).sum(axis=0)
    np.testing.assert_array_equal(st.stop_rises, rises)
    assert steps_sat.any() and steps_stop.any()


def test_batch_on_threads_equals_simulate_run_by_run(arm: Robot) -> None:
    """The batch entry point (`armcli tune`) gives each run's `simulate` result exactly, on
    threads too, diverged runs included."""
    require_native()
    ref = _reference(arm)
    weak = arm.with_limits(effort=np.array([3.0, 0.5]))
    free = arm.with_limits(effort=np.full(2, np.inf), lower=np.full(2, -1e3), upper=np.full(2, 1e3))
    runs = [
        Run(a, ref, np.zeros(2), 1.5, SimConfig(np.full(2, kp), np.full(2, kd), 1e-3, integ))
        for a, kp, kd, integ in cast(
            list[tuple[Robot, float, float, Integrator]],
            [
                (arm, 50, 5, "euler"),
                (weak, 200, 2, "euler"),
                (arm, 50, 1, "rk4"),
                (free, 1e8, 0, "euler"),  # far beyond the stability bound: diverges
            ],
        )
    ]
    batch = simulate_batch(runs, threads=3)
    assert sum(isinstance(r, SimulationError) for r in batch) == 1
    for run, got in zip(runs, batch, strict=True):
        try:
            want = simulate(run.robot, run.reference, run.q0, run.duration, run.cfg)
        except SimulationError as exc:
            assert isinstance(got, SimulationError) and str(got) == str(exc)
            continue
        assert not isinstance(got, SimulationError)
        np.testing.assert_array_equal(got.q, want.q)
        np.testing.assert_array_equal(got.tau, want.tau)


def test_missing_extension_is_an_error_saying_how_to_get_it(
    arm: Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ARMCLI_NO_NATIVE", "1")
    monkeypatch.setattr(native.ROLLOUT, "_loaded", None)  # asked again
    cfg = SimConfig(np.full(2, 50.0), np.full(2, 5.0), dt=1e-3)
    with pytest.raises(InputError, match=r"simulator is unavailable.*C\+\+ compiler") as exc:
        simulate(arm, _reference(arm), np.zeros(2), 0.2, cfg)
    assert "\n" not in str(exc.value)


def test_an_extension_built_from_other_source_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An editable install whose C++ changed without `make native` must not run."""
    require_native()
    edited = tmp_path / "rollout.cpp"
    edited.write_bytes(native.SOURCE.read_bytes() + b"// edited\n")
    monkeypatch.setattr(native.ROLLOUT, "sources", (edited,))
    monkeypatch.setattr(native.ROLLOUT, "_loaded", None)  # asked again
    assert native.load() is None and "built from another" in native.why_missing()


def test_the_type_stub_declares_exactly_what_the_extension_exports() -> None:
    """_rollout.pyi is written by hand from the bindings; the live module's names check it."""
    import ast

    mod = require_native()
    stub = ast.parse((Path(native.__file__).parent / "_rollout.pyi").read_text())
    declared: dict[str, set[str]] = {}
    for node in stub.body:
        if isinstance(node, ast.ClassDef):
            declared[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        elif isinstance(node, ast.FunctionDef):
            declared[node.name] = set()
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            declared[node.target.id] = set()
    public = {n for n in dir(mod) if not n.startswith("_")}
    assert set(declared) == public
    for name, members in declared.items():
        if members:
            assert members == {n for n in dir(getattr(mod, name)) if not n.startswith("_")}, name
