"""The model-based start: PD gains from the joint-space inertia, no rollouts.

Per joint j, over a sample of the joint range (`robot.sampling`, the one `check` takes;
Pinocchio CRBA), with m_j = max M_jj:

    kp_j = m_j wn_j²,   kd_j = 2 zeta sqrt(kp_j m_j) = 2 zeta wn_j m_j

so the joint, seen as a single inertia m_j, has natural frequency wn_j and damping ratio
zeta. wn_j is the smallest of three caps, and the binding one is reported:

- `target`: the requested wn, by default a decade under the controller's update rate
  (2 pi f_c / TARGET_RATIO), the usual rule for a sampled loop;
- `stability`: the loop chosen by `--loop` stays stable at STABILITY_MARGIN * dt, by the
  scalar-mode bound of `armcli.analysis.stability` (`implicit_dt_max` for armcli's simulator,
  `explicit_dt_max` for an explicitly stepped torque loop such as Gazebo's effort
  controller) with lambda_j = max (M^-1)_jj over the sample, the joint's own mode;
- `effort`: kp_j * (largest step of joint j) + max |g_j(q)| stays within the effort limit.

The full gain vector is then verified on every sampled M with the verdict of
`armcli.analysis.stability` (spectral radius of the real step maps, `worst_radius`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from armcli.analysis import pdloop
from armcli.analysis import stability as stab
from armcli.defaults import PD_LOOPS
from armcli.errors import InputError
from armcli.robot import sampling
from armcli.robot.model import Robot

TARGET_RATIO = 10.0  # wn <= 2 pi f_c / TARGET_RATIO for a loop closed at f_c [Hz]
STABILITY_MARGIN = 2.0  # gains must be stable at this multiple of dt
WN_BRACKET = (1e-6, 1e9)  # [rad/s] search interval for the stability cap
SCALE_FLOOR = 1e-9  # smallest common kp scale the coupled check tries
LOOPS = PD_LOOPS
Binding = Literal["target", "stability", "effort"]  # which cap chose a joint's wn


@dataclass(frozen=True)
class JointReasoning:
    """Why joint `name` got its start gains."""

    name: str
    m_min: float  # min M_jj over the sample [kg·m² or kg]
    m_max: float  # max M_jj (the inertia the gains are sized for)
    gravity_max: float  # max |g_j(q)| over the sample [N·m or N]
    step: float  # largest step in the trajectories [rad or m]
    lambda_j: float  # max (M^-1)_jj over the sample, the joint's mode [1/(kg·m²)]
    wn_target: float  # [rad/s]
    wn_stability: float  # [rad/s]
    wn_effort: float  # [rad/s] (inf without an effort limit)
    wn: float  # chosen [rad/s]
    zeta: float
    kp: float  # [N·m/rad]
    kd: float  # [N·m·s/rad]
    binding: Binding


@dataclass(frozen=True)
class StartGains:
    """The model-based gains and the evidence for them."""

    kp: np.ndarray
    kd: np.ndarray
    rows: tuple[JointReasoning, ...]
    lambda_max: float  # max lambda_max(M^-1) over the sample [1/(kg·m²)]
    lambda_joint: np.ndarray  # per joint, max (M^-1)_jj over the sample [1/(kg·m²)]
    loop: str
    dt: float  # [s]


def sample_configurations(robot: Robot) -> np.ndarray:
    """The joint-space sample `check` takes too (`robot.sampling.joint_space`), (N, n)."""
    return sampling.joint_space(sampling.bounds(robot.joints))


def linearised(robot: Robot, qs: np.ndarray, *, gravity: bool) -> pdloop.Linearised:
    """M(q) and gravity's stiffness at every sample, as the stability bound needs them.

    `gravity=False` (gravity compensation) gives zero stiffness.
    """
    return pdloop.linearise(robot, [robot.q(q) for q in qs], gravity=gravity)


def gravity_max(robot: Robot, qs: np.ndarray) -> np.ndarray:
    """Max |g(q)| per joint over the sample [N·m or N]."""
    worst = np.zeros(len(robot.names))
    for q in qs:
        worst = np.maximum(worst, np.abs(robot.gravity(robot.q(q))))
    return worst


def lambda_max(Ms: Sequence[np.ndarray]) -> float:
    """Largest eigenvalue of M^-1 over the sample [1/(kg·m²)]."""
    return max(float(np.linalg.eigvalsh(np.linalg.inv(M))[-1]) for M in Ms)


def dt_max(loop: str, kp: float, d: float, lam: float) -> float:
    """Largest stable dt for one mode, from `armcli.analysis.stability` [s]."""
    bound = stab.implicit_dt_max if loop == "implicit" else stab.explicit_dt_max
    return float(bound(kp, d, lam))


def _largest(ok: Callable[[float], bool], lo: float, hi: float) -> float:
    """Largest x in [lo, hi] with ok(x), for ok true below a threshold (log bisection)."""
    if ok(hi):
        return hi
    for _ in range(100):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo


def stability_cap(
    loop: str, m: float, zeta: float, damping: float, lam: float, dt: float, stiffness: float = 0.0
) -> float:
    """Largest wn whose gains keep the loop stable at STABILITY_MARGIN * dt [rad/s].

    `stiffness` is gravity's on the joint [N·m/rad], which adds to Kp in the bound.
    """

    def ok(wn: float) -> bool:
        kp, kd = m * wn * wn, 2.0 * zeta * wn * m
        return dt_max(loop, kp + stiffness, kd + damping, lam) >= STABILITY_MARGIN * dt

    return _largest(ok, *WN_BRACKET)


def start_gains(
    robot: Robot,
    *,
    dt: float,
    loop: str,
    zeta: float,
    wn_target: float,
    steps: np.ndarray,
    gravity: bool = True,
) -> StartGains:
    """Model-based kp, kd per joint (see the module docstring).

    Raises InputError when the effort limit cannot even hold the arm against gravity.
    """
    qs = sample_configurations(robot)
    lin = linearised(robot, qs, gravity=gravity)
    Ms = list(lin.M)
    lam = lambda_max(Ms)
    g_jj = np.max(np.maximum(np.diagonal(lin.G, axis1=1, axis2=2), 0.0), axis=0)
    lam_j = np.max([np.diag(np.linalg.inv(M)) for M in Ms], axis=0)
    g = gravity_max(robot, qs)
    diag = np.array([np.diag(M) for M in Ms])
    rows = []
    for j, name in enumerate(robot.names):
        m_max = float(diag[:, j].max())
        wn_s = stability_cap(
            loop, m_max, zeta, float(robot.damping[j]), float(lam_j[j]), dt, float(g_jj[j])
        )
        wn_e = _effort_cap(name, float(robot.effort[j]), float(g[j]), float(steps[j]), m_max)
        caps: dict[Binding, float] = {"target": wn_target, "stability": wn_s, "effort": wn_e}
        binding = min(caps, key=lambda k: caps[k])
        wn = caps[binding]
        kp_j, kd_j = m_max * wn * wn, 2.0 * zeta * wn * m_max
        rows.append(
            JointReasoning(
                name,
                float(diag[:, j].min()),
                m_max,
                float(g[j]),
                float(steps[j]),
                float(lam_j[j]),
                wn_target,
                wn_s,
                wn_e,
                wn,
                zeta,
                kp_j,
                kd_j,
                binding,
            )
        )
    kp = np.array([r.kp for r in rows])
    kd = np.array([r.kd for r in rows])
    scale = _coupled_scale(robot, lin, kp, kd, loop, dt)
    if scale < 1.0:
        kp, kd = kp * scale, kd * math.sqrt(scale)
        rows = [_scaled(r, scale) for r in rows]
    return StartGains(kp, kd, tuple(rows), lam, lam_j, loop, dt)


def _effort_cap(name: str, effort: float, g: float, step: float, m: float) -> float:
    if not math.isfinite(effort):
        return math.inf
    if g >= effort:
        raise InputError(
            f"joint {name!r}: gravity torque up to {g:.4g} exceeds the effort limit "
            f"{effort:g}; no PD gains can hold it (raise the limit or enable gravity "
            "compensation)",
            field="limit.effort",
        )
    if step <= 0.0:
        return math.inf
    return math.sqrt((effort - g) / (step * m))


def loop_stable(
    robot: Robot, lin: pdloop.Linearised, kp: np.ndarray, kd: np.ndarray, loop: str, dt: float
) -> bool:
    """The verdict of `armcli.analysis.stability` at every sample, for `loop` at dt."""
    pd = pdloop.PD.of(range(len(kp)), kp, kd, robot.damping)
    scheme: pdloop.Scheme = "implicit" if loop == "implicit" else "explicit"
    return stab.stable(lin, pd, dt, scheme)


def _coupled_scale(
    robot: Robot, lin: pdloop.Linearised, kp: np.ndarray, kd: np.ndarray, loop: str, dt: float
) -> float:
    """Common kp scale keeping the coupled loop stable at margin * dt (1 when it is).

    kd is scaled by sqrt(s), which keeps zeta. Raises InputError when even vanishing gains
    are unstable: gravity's stiffness alone is too much for the time step.
    """
    h = STABILITY_MARGIN * dt
    if loop_stable(robot, lin, kp, kd, loop, h):
        return 1.0
    if not loop_stable(robot, lin, kp * SCALE_FLOOR, kd * math.sqrt(SCALE_FLOOR), loop, h):
        scheme: pdloop.Scheme = "implicit" if loop == "implicit" else "explicit"
        free = pdloop.PD.of(range(len(kp)), 0.0 * kp, 0.0 * kd, robot.damping)
        edge = stab.largest_stable_dt(lin, free, scheme, dt)
        raise InputError(
            f"= {dt:g} s: gravity's stiffness alone makes the {loop} loop unstable at "
            f"{STABILITY_MARGIN:g} x dt, whatever the gains; use dt <= "
            f"{edge / STABILITY_MARGIN:.3g} s",
            field="control.dt",
        )
    return _largest(
        lambda s: loop_stable(robot, lin, s * kp, math.sqrt(s) * kd, loop, h), SCALE_FLOOR, 1.0
    )


def _scaled(r: JointReasoning, s: float) -> JointReasoning:
    from dataclasses import replace

    return replace(
        r, kp=r.kp * s, kd=r.kd * math.sqrt(s), wn=r.wn * math.sqrt(s), binding="stability"
    )
