"""The steady state of a PD(+I) hold against gravity, against a pendulum's closed form.

A single link of mass m whose centre of mass is l from a revolute joint about y: its
centre sits at (l cos q, 0, -l sin q), so the potential is -m g l sin q and the gravity
torque g(q) = -m g l cos q. A hold `Kp (q_ref - q) + I = g(q)` with the integral term
capped at i_max settles where `Kp (q_ref - q) = -m g l cos q + clip(m g l cos q, ±i_max)`,
found here by bisection (scalar, independent of the Newton solver and of Pinocchio).
"""

from __future__ import annotations

import math

import pytest

from armcli.analysis.sag import Hold, passing_kp, settle
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf

M, L, G = 2.0, 0.4, 9.81  # [kg, m, m/s²]
TOL = 1e-9  # [rad] Newton to tolerance vs bisection to 1e-14

PENDULUM = f"""<robot name="pendulum">
  <link name="base"/>
  <link name="arm">
    <inertial><origin xyz="{L} 0 0"/><mass value="{M}"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="1.2" effort="100" velocity="5"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.load(parse_urdf(PENDULUM.encode(), "pendulum.urdf"), strict=False)


def closed_form(q_ref: float, kp: float, i_max: float = 0.0) -> float:
    """Bisection on Kp (q_ref - q) + m g l cos q - clip(m g l cos q, ±i_max) = 0."""

    def f(q: float) -> float:
        held = M * G * L * math.cos(q)
        return kp * (q_ref - q) + held - max(-i_max, min(i_max, held))

    lo, hi = q_ref - 2.0, q_ref + 2.0  # f(lo) > 0 > f(hi) for these gains
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("q_ref", [-1.0, -0.3, 0.0, 0.5])
@pytest.mark.parametrize("kp", [20.0, 80.0])
def test_pd_hold_matches_the_pendulums_closed_form(robot: Robot, q_ref: float, kp: float) -> None:
    sag = settle(robot, {"j": q_ref}, Hold.pd(["j"], [kp]))
    assert sag.converged
    assert sag.q["j"] == pytest.approx(closed_form(q_ref, kp), abs=TOL)
    assert sag.torque["j"] == pytest.approx(-M * G * L * math.cos(sag.q["j"]), abs=1e-9)


def test_integral_term_carries_gravity_up_to_its_clamp(robot: Robot) -> None:
    full = settle(robot, {"j": 0.0}, Hold(("j",), (30.0,), (math.inf,)))
    assert full.deviation("j") == pytest.approx(0.0, abs=TOL)
    half = M * G * L / 2
    capped = settle(robot, {"j": 0.0}, Hold(("j",), (30.0,), (half,)))
    assert capped.q["j"] == pytest.approx(closed_form(0.0, 30.0, half), abs=TOL)


def test_a_joint_stop_holds_what_the_gains_do_not(robot: Robot) -> None:
    # commanded at the upper stop (1.2 rad); gravity pushes it up (q grows): the stop holds
    sag = settle(robot, {"j": 1.2}, Hold.pd(["j"], [5.0]))
    assert sag.converged and sag.q["j"] == pytest.approx(1.2)


def test_passing_kp_holds_within_the_tolerance(robot: Robot) -> None:
    tol = 0.01
    kp = passing_kp(robot, {"j": 0.0}, Hold.pd(["j"], [20.0]), tol)
    assert settle(robot, {"j": 0.0}, Hold.pd(["j"], [kp])).deviation("j") <= tol
    least = M * G * L * math.cos(tol) / tol  # the gain that sags exactly tol (closed form)
    assert least <= kp <= 1.2 * least
