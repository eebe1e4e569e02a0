"""The controller's loop at its update rate against an independent zero-order-hold simulation.

The reference is written here: Pinocchio's forward dynamics (ABA) integrated by RK4 at
HOLD/SUBSTEPS, the joint damping applied continuously, and a PID computed from the state
sampled every hold and held until the next (what gz_ros2_control does with the
JointTrajectoryController's effort). Against it: the linear held map of analysis.zoh
(state after each hold), the largest stable hold (the simulation decays below it and grows
above it), the course arm's gains at 100 Hz (the rate the specs had: divergence at
`reach`) and 1000 Hz (settles), and the remedies the verdict suggests. A single pendulum
swinging in a horizontal plane has the closed form of tests/analysis/test_zoh.py.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pytest

from armcli.analysis import pdloop, rate, zoh
from armcli.robot import sampling
from armcli.robot.model import Robot
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import spec_urdfs
from tests.helpers import DEFAULT_SPEC

SUBSTEPS = 20  # RK4 steps per hold: the plant to ~1e-9 relative per hold here
MAP_RTOL = 1e-6  # the held map against the simulation from a 1e-6 rad perturbation (the
# linearisation's error is second order in it; measured ~1e-8)
EPS = 1e-6  # [rad] the perturbation
EDGE = (0.95, 1.05)  # holds either side of the largest stable one
EDGE_HOLDS = 400
SETTLED = 1e-3  # [rad/s] joint speed left after SETTLE_S of holding
SETTLE_S = 1.5  # [s] of holding a pose
SLOW_SETTLE_S = 3.0  # [s] for the remedy's lower gains (at 100 Hz: p 10, d 0.32; ~2.5 s)
DIVERGED = 0.3  # [rad] farther than this from the command: diverged


class Held:
    """The arm driven by a sampled PID whose torque is held between updates (the reference)."""

    def __init__(self, robot: Robot, joints: Sequence[str], p: Sequence[float],
                 d: Sequence[float], i: Sequence[float] | None = None) -> None:  # fmt: skip
        self.robot, self.model, self.data = robot, robot.model, robot.model.createData()
        self.v_idx = [robot.joint(j).idx_v for j in joints]
        self.q_idx = [robot.joint(j).idx_q for j in joints]
        self.p, self.d = np.array(p, dtype=float), np.array(d, dtype=float)
        self.i = np.zeros(len(joints)) if i is None else np.array(i, dtype=float)
        self.damping = np.array([robot.joint(j).damping for j in joints])

    def _accel(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        import pinocchio as pin

        t = tau.copy()
        t[self.v_idx] -= self.damping * v[self.v_idx]
        return np.asarray(pin.aba(self.model, self.data, q, v, t))

    def _rk4(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, h: float) -> tuple:
        import pinocchio as pin

        m = self.model
        a1 = self._accel(q, v, tau)
        v2 = v + a1 * h / 2
        a2 = self._accel(pin.integrate(m, q, v * h / 2), v2, tau)
        v3 = v + a2 * h / 2
        a3 = self._accel(pin.integrate(m, q, v2 * h / 2), v3, tau)
        v4 = v + a3 * h
        a4 = self._accel(pin.integrate(m, q, v3 * h), v4, tau)
        q = pin.integrate(m, q, (v + 2 * v2 + 2 * v3 + v4) * h / 6)
        return q, v + (a1 + 2 * a2 + 2 * a3 + a4) * h / 6

    def run(self, q0: np.ndarray, ref: np.ndarray, hold: float, holds: int) -> np.ndarray:
        """(holds, 2n) the controlled joints' (q - ref, v) at each update, NaN once diverged."""
        q, v = q0.copy(), np.zeros(self.model.nv)
        integral = np.zeros(len(self.p))
        out = np.full((holds, 2 * len(self.p)), np.nan)
        for k in range(holds):
            if not np.all(np.isfinite(q)) or np.max(np.abs(q[self.q_idx] - ref)) > 10.0:
                break
            out[k] = np.concatenate([q[self.q_idx] - ref, v[self.v_idx]])
            e = ref - q[self.q_idx]
            integral += self.i * hold * e
            tau = np.zeros(self.model.nv)
            tau[self.v_idx] = self.p * e - self.d * v[self.v_idx] + integral
            for _ in range(SUBSTEPS):
                q, v = self._rk4(q, v, tau, hold / SUBSTEPS)
        return out


@pytest.fixture(scope="module")
def course() -> tuple[Robot, list[str], pdloop.PD, list, pdloop.Linearised]:
    spec = load_spec(DEFAULT_SPEC)
    xml = spec_urdfs(spec)["standalone_arm.urdf"]
    robot = Robot.load(parse_urdf(xml, "standalone_arm.urdf"), strict=False)
    names = list(spec.control.gains)
    gains = [spec.control.gains[n] for n in names]
    pd = pdloop.PD.of([robot.joint(n).idx_v for n in names], [g.kp for g in gains],
                      [g.kd for g in gains], [robot.joint(n).damping for n in names])  # fmt: skip
    samples = sampling.configurations(robot)
    lin = pdloop.linearise(robot, [q for _, q in samples])
    return robot, names, pd, samples, lin


def _balanced_ref(robot: Robot, names: Sequence[str], kp: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The command whose P term carries gravity at q: the loop's equilibrium is q itself."""
    import pinocchio as pin

    g = pin.computeGeneralizedGravity(robot.model, robot.data, q)
    return np.array([q[robot.joint(n).idx_q] + g[robot.joint(n).idx_v] / k
                     for n, k in zip(names, kp, strict=True)])  # fmt: skip


def test_the_held_map_is_the_simulation(course) -> None:
    robot, names, pd, samples, lin = course
    pid = zoh.Pid.of(pd)
    v = rate.rate_verdict(lin, pid, 100.0)
    q_star = samples[v.worst][1]
    sim = Held(robot, names, pd.kp, pd.kd)
    ref = _balanced_ref(robot, names, pd.kp, q_star)
    qi = [robot.joint(n).idx_q for n in names]
    one = zoh.reduce(lin, pid).take(np.arange(len(lin)) == v.worst)
    for f in (0.5, 0.98, 1.02):
        hold = f * v.hold_max
        q0 = q_star.copy()
        q0[robot.joint(names[1]).idx_q] += EPS
        got = sim.run(q0, ref, hold, 50)
        got[:, : len(names)] += ref - q_star[qi]  # relative to q*, the linearisation point
        A = zoh.closed_loop(one, pid, hold)[0]
        x = got[0].copy()
        for k in range(1, len(got)):
            x = A @ x
            assert np.max(np.abs(x - got[k])) <= MAP_RTOL * np.max(np.abs(got[k])), (f, k)


def test_largest_hold_is_the_simulations_edge(course) -> None:
    robot, names, pd, samples, lin = course
    v = rate.rate_verdict(lin, zoh.Pid.of(pd), 100.0)
    q_star = samples[v.worst][1]
    sim = Held(robot, names, pd.kp, pd.kd)
    ref = _balanced_ref(robot, names, pd.kp, q_star)
    q0 = q_star.copy()
    q0[robot.joint(names[1]).idx_q] += EPS
    qi = [robot.joint(n).idx_q for n in names]
    size = []
    for f in EDGE:
        run = sim.run(q0, ref, f * v.hold_max, EDGE_HOLDS)
        size.append(np.max(np.abs(run[-20:, : len(names)] + ref - q_star[qi])))
    assert size[0] < EPS and size[1] > 10 * EPS  # decays below the edge, grows above it


def _hold_pose(robot: Robot, names: Sequence[str], pose: Mapping[str, float], gains: tuple,
               rate_hz: float, seconds: float = SETTLE_S) -> np.ndarray:  # fmt: skip
    """The arm commanded to `pose`, starting there at rest, for `seconds` at `rate_hz`."""
    q0 = robot.q(robot.follow(dict(pose)))
    ref = np.array([pose[n] for n in names])
    return Held(robot, names, *gains).run(q0, ref, 1.0 / rate_hz, round(seconds * rate_hz))


def _settled(run: np.ndarray, n: int) -> bool:
    return bool(np.all(np.isfinite(run[-1])) and np.max(np.abs(run[-1, n:])) < SETTLED)


def _diverged(run: np.ndarray, n: int) -> bool:
    return bool(np.any(~np.isfinite(run)) or np.nanmax(np.abs(run[:, :n])) > DIVERGED)


def test_course_gains_diverge_at_100_hz_and_hold_at_1000(course) -> None:
    robot, names, pd, _, lin = course
    spec = load_spec(DEFAULT_SPEC)
    reach = spec.pose("reach")
    gains = (pd.kp, pd.kd)
    assert _diverged(_hold_pose(robot, names, reach, gains, 100.0), len(names))
    assert _settled(_hold_pose(robot, names, reach, gains, 1000.0), len(names))
    verdicts = {hz: rate.rate_verdict(lin, zoh.Pid.of(pd), hz).stable for hz in (100.0, 1000.0)}
    assert verdicts == {100.0: False, 1000.0: True}


def test_the_remedies_hold_the_arm(course) -> None:
    robot, names, pd, _, lin = course
    reach = load_spec(DEFAULT_SPEC).pose("reach")
    v = rate.rate_verdict(lin, zoh.Pid.of(pd), 100.0)
    r = v.remedy
    assert r is not None and r.rate is not None and r.kp is not None and r.kd is not None
    assert 1.0 / r.rate <= v.hold_max  # the rate is inside the edge
    assert _settled(_hold_pose(robot, names, reach, (pd.kp, pd.kd), r.rate), len(names))
    slow = _hold_pose(robot, names, reach, (r.kp, r.kd), 100.0, SLOW_SETTLE_S)
    assert _settled(slow, len(names))


PENDULUM = """<robot name="pendulum">
  <link name="base"/>
  <link name="bob">
    <inertial><origin xyz="{l} 0 0"/><mass value="{m}"/>
      <inertia ixx="1e-9" iyy="1e-9" izz="1e-9" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="swing" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="0 0 {axis}"/><limit lower="-3" upper="3" effort="100" velocity="10"/>
    <dynamics damping="0"/></joint>
</robot>"""


@pytest.mark.parametrize(("kp", "kd"), [(50.0, 1.5), (50.0, 0.02), (2.0, 0.05)])
def test_single_pendulum_in_a_horizontal_plane_is_the_closed_form(kp: float, kd: float) -> None:
    m, length = 0.3, 0.45
    robot = Robot.load(
        parse_urdf(PENDULUM.format(l=length, m=m, axis=1).encode(), "p"), strict=False
    )
    samples = sampling.configurations(robot)
    lin = pdloop.linearise(robot, [q for _, q in samples])
    pd = pdloop.PD.of([0], [kp], [kd], [0.0])
    inertia = m * length**2 + 1e-9  # point mass on a massless rod, plus the URDF's izz
    # Jury on the held double integrator (tests/analysis/test_zoh.py): the edge of a / 2 < b < 2
    want = min(2 * kd / kp, 2 * inertia / kd)
    got = rate.rate_verdict(lin, zoh.Pid.of(pd), 1.0 / (0.5 * want)).hold_max
    assert got == pytest.approx(want, rel=1e-5)  # tests/analysis/test_zoh.py's HOLD_RTOL


def test_hanging_pendulum_edge_in_the_simulation() -> None:
    # axis y: gravity's stiffness m g l at the bottom, the swing's own frequency 4.7 rad/s
    m, length, kp, kd = 0.3, 0.45, 50.0, 1.5
    xml = PENDULUM.format(l=length, m=m, axis=0).replace('xyz="0 0 0"', 'xyz="0 1 0"')
    robot = Robot.load(parse_urdf(xml.encode(), "p"), strict=False)
    samples = sampling.configurations(robot)
    lin = pdloop.linearise(robot, [q for _, q in samples])
    pd = pdloop.PD.of([0], [kp], [kd], [0.0])
    v = rate.rate_verdict(lin, zoh.Pid.of(pd), 100.0)
    q_star = samples[v.worst][1]
    sim = Held(robot, ["swing"], [kp], [kd])
    ref = _balanced_ref(robot, ["swing"], pd.kp, q_star)
    q0 = q_star + EPS
    size = [
        np.max(np.abs(sim.run(q0, ref, f * v.hold_max, EDGE_HOLDS)[-20:, :1] + ref - q_star))
        for f in EDGE
    ]
    assert size[0] < EPS and size[1] > 10 * EPS
    assert not math.isinf(v.hold_max)
