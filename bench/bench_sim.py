"""Benchmark: armcli's step loop vs MuJoCo driven from Python, same model/trajectory/dt.

Run with `make bench` (or `python bench/bench_sim.py [--quick]`). Prints tables of µs per
step (medians of repeats), the ratio to MuJoCo's Python loop, the maximum deviation
between the two engines, and how cost grows with steps and with a batch of independent
rollouts. Not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from armcli.sim import native  # noqa: E402
from armcli.sim import rollout as ro  # noqa: E402
from armcli.sim.reference import build_reference  # noqa: E402
from armcli.sim.simulate import (  # noqa: E402
    SimConfig,
    arm_from_model,
    params_of,
    simulate,
)
from armcli.sim.trajectory import loads_trajectory  # noqa: E402
from armcli.urdf.pinocchio import load_model  # noqa: E402

DT = 1e-3  # [s] the spec's control.dt
KP, KD = 50.0, 5.0
Q0 = np.array([0.2, 0.2])
TRAJ = (
    "joint_names: [arm_base_forearm_joint, forearm_hand_joint]\npoints:\n"
    " - {positions: [0.6, 0.4], time_from_start: 1.0}\n"
    " - {positions: [0.9, 1.2], time_from_start: 2.0}\n"
    " - {positions: [0.9, 1.2], time_from_start: 2.5}\n"
    " - {positions: [0.5, 0.8], time_from_start: 3.5}\n"
    " - {positions: [0.3, 0.3], time_from_start: 5.0}\n"
)  # pick-like, clear of the joint stops (MuJoCo's limits are soft, armcli's hard)


def setup(urdf: Path, friction: bool):
    arm = arm_from_model(load_model(urdf).model)
    if not friction:
        arm = replace(arm, friction=np.zeros(2))
    tr = loads_trajectory(TRAJ, dict.fromkeys(arm.joint_names, (0.0, math.pi / 2)))
    return arm, build_reference(tr, arm.joint_names, Q0)


def mujoco_model(urdf: Path, friction: bool):
    import mujoco

    xml = urdf.read_text(encoding="utf-8").replace(
        "</robot>", '<mujoco><compiler discardvisual="true" fusestatic="false"/></mujoco></robot>'
    )
    m = mujoco.MjModel.from_xml_string(xml)
    m.opt.timestep = DT
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER  # implicit dof damping, like armcli
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    m.dof_damping[:] = m.dof_damping + KD
    if not friction:
        m.dof_frictionloss[:] = 0.0
    return m


def mujoco_actuated(urdf: Path):
    """The same plant with the PD as affine actuators, so mujoco.rollout runs it all in C:
    force = Kp ctrl - Kp q with ctrl = q_ref + (Kd/Kp) v_ref, Kd implicit in dof_damping."""
    import mujoco

    xml = urdf.read_text(encoding="utf-8").replace(
        "</robot>", '<mujoco><compiler discardvisual="true" fusestatic="false"/></mujoco></robot>'
    )
    spec = mujoco.MjSpec.from_string(xml)
    for j in ("arm_base_forearm_joint", "forearm_hand_joint"):
        a = spec.add_actuator()
        a.target, a.trntype = j, mujoco.mjtTrn.mjTRN_JOINT
        a.gainprm[0] = KP
        a.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        a.biasprm[:3] = [0.0, -KP, 0.0]
    m = spec.compile()
    m.opt.timestep = DT
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    m.dof_damping[:] = m.dof_damping + KD
    m.dof_frictionloss[:] = 0.0
    return m


def mujoco_c_rollout(m, q_ref: np.ndarray, v_ref: np.ndarray) -> np.ndarray:
    import mujoco
    from mujoco import rollout

    d = mujoco.MjData(m)
    d.qpos[:] = Q0
    kind = mujoco.mjtState.mjSTATE_FULLPHYSICS  # [time, qpos, qvel] for this model
    state0 = np.zeros((1, mujoco.mj_stateSize(m, kind)))
    mujoco.mj_getState(m, d, state0[0], kind)
    ctrl = (q_ref + KD / KP * v_ref)[:-1][None]
    states, _ = rollout.rollout(m, d, state0, ctrl)
    return np.vstack([Q0, states[0, :, 1 : 1 + m.nq]])


def mujoco_loop(m, q_ref: np.ndarray, v_ref: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """The PD loop in Python around mj_step: what a user would write."""
    import mujoco

    d = mujoco.MjData(m)
    d.qpos[:] = q0
    out = np.empty_like(q_ref)
    out[0] = d.qpos
    for k in range(q_ref.shape[0] - 1):
        d.qfrc_applied[:] = KP * (q_ref[k] - d.qpos) + KD * v_ref[k]
        mujoco.mj_step(m, d)
        out[k + 1] = d.qpos
    return out


def timed(fn, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def refs(reference, steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    q_ref, v_ref = reference.sample(np.arange(steps + 1) * DT)
    return q_ref, v_ref, np.ascontiguousarray(np.hstack([q_ref, v_ref]))


def row(*cells: object) -> str:
    return "  ".join(f"{c:>14}" if i else f"{c:<34}" for i, c in enumerate(cells))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer repeats and steps")
    args = ap.parse_args()
    reps = 3 if args.quick else 5
    urdf = ROOT / "urdf" / "standalone_arm.urdf"
    lib = native.load()
    if lib is None:
        print("note: compiled rollout not built (`make native`); armcli uses the Python loop")
    arm, reference = setup(urdf, friction=False)
    cfg = SimConfig(np.full(2, KP), np.full(2, KD), dt=DT)
    plant = ro.Plant(arm.model, params_of(arm, cfg), False, DT, "euler", math.inf)
    m = mujoco_model(urdf, friction=False)

    steps = 10_000
    q_ref, v_ref, ref = refs(reference, steps)
    t_mj = timed(lambda: mujoco_loop(m, q_ref, v_ref, Q0), reps) / steps
    t_sim = timed(lambda: simulate(arm, reference, Q0, steps * DT, cfg), reps) / steps
    m_c = mujoco_actuated(urdf)
    t_mjc = timed(lambda: mujoco_c_rollout(m_c, q_ref, v_ref), reps) / steps
    rows = [("MuJoCo mj_step, PD in Python", t_mj), ("MuJoCo mujoco.rollout (C)", t_mjc)]
    if lib is not None:
        t_nat = timed(lambda: native.rollout(lib, plant, Q0, np.zeros(2), ref), reps) / steps
        rows.append(("armcli compiled rollout", t_nat))
    py_steps = 1000 if args.quick else 2000
    _, _, ref_py = refs(reference, py_steps)
    t_py = timed(lambda: ro.rollout_python(plant, Q0, np.zeros(2), ref_py), 1) / py_steps
    rows += [("armcli Python loop (fallback)", t_py), ("armcli simulate() incl. sampling", t_sim)]
    print(f"\nsame model (standalone arm), trajectory (5 points, {steps * DT:g} s), dt = {DT} s")
    print(row("engine", "µs/step", "x MuJoCo loop"))
    for name, t in rows:
        print(row(name, f"{t * 1e6:.2f}", f"{t / t_mj:.2f}"))

    res = simulate(arm, reference, Q0, steps * DT, cfg)
    dev = np.max(np.abs(res.q - mujoco_loop(m, res.q_ref, res.v_ref, Q0)))
    arm_f, _ = setup(urdf, friction=True)
    res_f = simulate(arm_f, reference, Q0, steps * DT, cfg)
    m_f = mujoco_model(urdf, friction=True)
    dev_f = np.max(np.abs(res_f.q - mujoco_loop(m_f, res_f.q_ref, res_f.v_ref, Q0)))
    dev_c = np.max(np.abs(res.q - mujoco_c_rollout(m_c, res.q_ref, res.v_ref)))
    print(f"\nmax |q_armcli - q_mujoco|: {dev:.2e} rad friction off, {dev_f:.2e} rad friction on")
    print(f"max |q_armcli - q_mujoco.rollout|: {dev_c:.2e} rad friction off")

    print("\nscaling with steps (µs/step)")
    print(row("steps", "armcli", "MuJoCo loop"))
    for n_steps in (1_000, 10_000, 100_000):
        q_r, v_r, r = refs(reference, n_steps)
        fn = (lambda r=r: native.rollout(lib, plant, Q0, np.zeros(2), r)) if lib else None
        t_a = timed(fn, reps) / n_steps if fn else float("nan")
        t_m = (
            timed(
                lambda q_r=q_r, v_r=v_r: mujoco_loop(m, q_r, v_r, Q0),
                1 if n_steps > 10_000 else reps,
            )
            / n_steps
        )
        print(row(n_steps, f"{t_a * 1e6:.2f}", f"{t_m * 1e6:.2f}"))

    print("\nscaling with a batch of independent rollouts, 2000 steps each (µs/step/rollout)")
    print(row("batch", "armcli", "MuJoCo loop"))
    q_r, v_r, r = refs(reference, 2000)
    rng = np.random.default_rng(0)
    for batch in (1, 10, 100):
        q0s = Q0 + rng.uniform(-0.1, 0.1, size=(batch, 2))
        v0s = np.zeros((batch, 2))
        t_a = float("nan")
        if lib is not None:
            t_a = timed(
                lambda q0s=q0s, v0s=v0s: native.rollout_batch(lib, plant, q0s, v0s, r), reps
            )
            t_a /= batch * 2000
        t_m = timed(lambda q0s=q0s: [mujoco_loop(m, q_r, v_r, q0) for q0 in q0s], 1) / (
            batch * 2000
        )
        print(row(batch, f"{t_a * 1e6:.2f}", f"{t_m * 1e6:.2f}"))


if __name__ == "__main__":
    main()
