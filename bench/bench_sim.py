"""Benchmark: armcli's compiled step vs MuJoCo driven from Python, same model/trajectory/dt.

Run with `make bench` (or `python bench/bench_sim.py [--quick]`). Prints µs per step
(medians of repeats, CPU time of this process) and the ratio to MuJoCo's Python loop,
the maximum deviation between armcli and MuJoCo, and the cost per step of a batch of
independent rollouts on 1 and 2 threads. Not a test: numbers depend on the machine and
its load.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from armcli.robot.model import Robot  # noqa: E402
from armcli.sim import native  # noqa: E402
from armcli.sim import rollout as ro  # noqa: E402
from armcli.sim.simulate import (  # noqa: E402
    Run,
    SimConfig,
    plant_of,
    simulate,
    simulate_batch,
    simulated,
)
from armcli.trajectory.message import loads_trajectory  # noqa: E402
from armcli.trajectory.reference import build_reference  # noqa: E402
from armcli.urdf.read import read_urdf  # noqa: E402

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
    arm = simulated(Robot.load(read_urdf(urdf)))
    if not friction:
        arm = arm.with_limits(friction=np.zeros(2))
    tr = loads_trajectory(TRAJ, dict.fromkeys(arm.names, (0.0, math.pi / 2)))
    return arm, build_reference(tr, arm.names, Q0)


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


def timed(fn, repeats: int, clock=time.process_time) -> float:
    """Median time of `fn`.

    Single-threaded runs use the process's CPU time, which other jobs on a shared machine
    disturb far less than the wall clock; threaded batches pass the wall clock (their
    point is the elapsed time).
    """
    times = []
    for _ in range(repeats):
        t = clock()
        fn()
        times.append(clock() - t)
    return statistics.median(times)


def refs(reference, steps: int) -> tuple[np.ndarray, np.ndarray]:
    return reference.sample(np.arange(steps + 1) * DT)


def row(*cells: object) -> str:
    return "  ".join(f"{c:>14}" if i else f"{c:<38}" for i, c in enumerate(cells))


def engine_only(plant, reference, steps: int) -> None:
    """The compiled rollout alone, keeping only the last state."""
    ro.run(plant, reference, Q0, np.zeros(2), steps, record=np.array([steps]))


def per_step(args, arm, reference, plant, m, m_c) -> float:
    """µs per step on the same 10 s run; returns MuJoCo's loop time."""
    reps = 3 if args.quick else 5
    steps = 10_000
    q_ref, v_ref = refs(reference, steps)
    cfg = SimConfig(np.full(2, KP), np.full(2, KD), dt=DT)
    t_mj = timed(lambda: mujoco_loop(m, q_ref, v_ref, Q0), reps) / steps
    t_mjc = timed(lambda: mujoco_c_rollout(m_c, q_ref, v_ref), reps) / steps
    t_nat = timed(lambda: engine_only(plant, reference, steps), reps) / steps
    t_sim = timed(lambda: simulate(arm, reference, Q0, steps * DT, cfg), reps) / steps
    rows = [
        ("MuJoCo mj_step, PD in Python", t_mj),
        ("MuJoCo mujoco.rollout (C)", t_mjc),
        ("armcli compiled rollout", t_nat),
        ("armcli simulate(), every step kept", t_sim),
    ]
    print(f"\nsame model (standalone arm), trajectory (5 points, {steps * DT:g} s), dt = {DT} s")
    print("friction off (MuJoCo's frictionloss is a soft constraint; this is the like-for-like)")
    print(row("engine", "µs/step", "x MuJoCo loop"))
    for name, t in rows:
        print(row(name, f"{t * 1e6:.2f}", f"{t / t_mj:.3f}"))
    return t_mj


def per_step_friction(args, urdf: Path, reference) -> None:
    """The seed arm as its URDF has it: Coulomb friction 0.05 N·m on both joints."""
    reps = 3 if args.quick else 5
    steps = 10_000
    q_ref, v_ref = refs(reference, steps)
    arm_f, _ = setup(urdf, friction=True)
    plant = plant_of(arm_f, SimConfig(np.full(2, KP), np.full(2, KD), dt=DT))
    m_f = mujoco_model(urdf, friction=True)
    t_mj = timed(lambda: mujoco_loop(m_f, q_ref, v_ref, Q0), reps) / steps
    t_nat = timed(lambda: engine_only(plant, reference, steps), reps) / steps
    print("\nfriction on (URDF: 0.05 N·m per joint; MuJoCo frictionloss)")
    print(row("engine", "µs/step", "x MuJoCo loop"))
    for name, t in (("MuJoCo mj_step, PD in Python", t_mj), ("armcli compiled rollout", t_nat)):
        print(row(name, f"{t * 1e6:.2f}", f"{t / t_mj:.3f}"))


def agreement(arm, reference, urdf: Path, m, m_c) -> None:
    steps = 10_000
    cfg = SimConfig(np.full(2, KP), np.full(2, KD), dt=DT)
    res = simulate(arm, reference, Q0, steps * DT, cfg)
    dev = np.max(np.abs(res.q - mujoco_loop(m, res.q_ref, res.v_ref, Q0)))
    arm_f, _ = setup(urdf, friction=True)
    res_f = simulate(arm_f, reference, Q0, steps * DT, cfg)
    m_f = mujoco_model(urdf, friction=True)
    dev_f = np.max(np.abs(res_f.q - mujoco_loop(m_f, res_f.q_ref, res_f.v_ref, Q0)))
    dev_c = np.max(np.abs(res.q - mujoco_c_rollout(m_c, res.q_ref, res.v_ref)))
    print(f"\nmax |q_armcli - q_mujoco|: {dev:.2e} rad friction off, {dev_f:.2e} rad friction on")
    print(f"max |q_armcli - q_mujoco.rollout|: {dev_c:.2e} rad friction off")


def batch_scaling(arm, reference, m_c) -> None:
    """Independent rollouts (different initial states) on 1 and 2 threads, next to
    mujoco.rollout's own thread pool; µs per step per rollout."""
    import mujoco

    steps = 2000
    q_r, v_r = refs(reference, steps)
    rng = np.random.default_rng(0)
    threads = (1, 2)
    cfg = SimConfig(np.full(2, KP), np.full(2, KD), dt=DT)
    print(f"\nbatch of independent rollouts, {steps} steps each (µs/step/rollout)")
    print(
        row(
            "batch",
            *[f"armcli {t} thr" for t in threads],
            *[f"mj.rollout {t} thr" for t in threads],
        )
    )
    for batch in (1, 10, 100):
        q0s = Q0 + rng.uniform(-0.1, 0.1, size=(batch, 2))
        runs = [Run(arm, reference, q0, steps * DT, cfg) for q0 in q0s]
        cells = []
        for t in threads:
            secs = timed(lambda t=t, runs=runs: simulate_batch(runs, threads=t), 3,
                         time.perf_counter)  # fmt: skip
            cells.append(f"{secs / (batch * steps) * 1e6:.3f}")
        kind = mujoco.mjtState.mjSTATE_FULLPHYSICS
        d = mujoco.MjData(m_c)
        states = np.zeros((batch, mujoco.mj_stateSize(m_c, kind)))
        for b in range(batch):
            d.qpos[:] = q0s[b]
            mujoco.mj_getState(m_c, d, states[b], kind)
        ctrl = (q_r + KD / KP * v_r)[:-1][None]
        for t in threads:
            datas = [mujoco.MjData(m_c) for _ in range(t)]
            secs = timed(
                lambda datas=datas, states=states, ctrl=ctrl: rollout_mj(m_c, datas, states, ctrl),
                3,
                time.perf_counter,
            )
            cells.append(f"{secs / (batch * steps) * 1e6:.3f}")
        print(row(batch, *cells))


def rollout_mj(m, datas, states, ctrl):
    from mujoco import rollout

    return rollout.rollout(m, datas if len(datas) > 1 else datas[0], states, ctrl)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer repeats and steps")
    args = ap.parse_args()
    urdf = ROOT / "urdf" / "standalone_arm.urdf"
    native.require()
    arm, reference = setup(urdf, friction=False)
    plant = plant_of(arm, SimConfig(np.full(2, KP), np.full(2, KD), dt=DT))
    m = mujoco_model(urdf, friction=False)
    m_c = mujoco_actuated(urdf)
    per_step(args, arm, reference, plant, m, m_c)
    per_step_friction(args, urdf, reference)
    agreement(arm, reference, urdf, m, m_c)
    batch_scaling(arm, reference, m_c)


if __name__ == "__main__":
    main()
