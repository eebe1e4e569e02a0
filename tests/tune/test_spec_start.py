"""Start gains written by `armcli import` (tune.spec_start): stable in both loops `check`
judges, so an imported spec passes `check` at once (issue 31: the imported
OpenManipulator-X got `pd-explicit-unstable`, its implicit-loop Kd too high for Gazebo's)."""

from __future__ import annotations

import numpy as np
import pytest

from armcli.robot.model import Robot
from armcli.sim.simulate import simulated
from armcli.tune.model_gains import linearised, loop_stable, sample_configurations
from armcli.tune.spec_start import KD_MARGIN, _explicit_kd
from tests.helpers import FIXTURES, load_robot

URDF = FIXTURES / "tune" / "pendulum.urdf"
M_PENDULUM = 0.01 + 2.0 * 0.5**2  # [kg·m²] izz + m r² from the fixture (vertical axis)
DT = 0.01  # [s] coarse, so a critically damped wn = 1 / DT is explicitly unstable
WN = 1.0 / DT  # [rad/s] wn h = 1: implicit x² < 4 + 4x holds, explicit x² + 4x < 4 fails
BISECT_REL_TOL = 1e-3


@pytest.fixture(scope="module")
def arm() -> Robot:
    return simulated(load_robot(URDF))


def test_kd_lowered_to_the_explicit_bound(arm: Robot) -> None:
    kp = np.array([M_PENDULUM * WN**2])
    kd = np.array([2.0 * WN * M_PENDULUM])  # zeta = 1
    lin = linearised(arm, sample_configurations(arm), gravity=True)
    assert not loop_stable(arm, lin, kp, kd, "explicit", DT)  # the case the import hit
    got = _explicit_kd(arm, kp, kd, DT)
    # One mode, semi-implicit Euler with explicit damping D = Kd + d is stable while
    # 4 m - dt² kp - 2 dt D > 0 (the Jury bound in armcli.analysis.stability): Kd < kd_edge.
    kd_edge = (4.0 * M_PENDULUM - DT**2 * kp[0]) / (2.0 * DT) - arm.damping[0]
    assert got[0] == pytest.approx(KD_MARGIN * kd_edge, rel=BISECT_REL_TOL)
    assert loop_stable(arm, lin, kp, got, "explicit", DT)
    assert loop_stable(arm, lin, kp, got, "implicit", DT)  # the simulator's loop too


def test_stable_gains_are_kept(arm: Robot) -> None:
    kp, kd = np.array([1.0]), np.array([0.1])
    assert _explicit_kd(arm, kp, kd, DT).tolist() == kd.tolist()
