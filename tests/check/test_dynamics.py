"""`check`'s dynamics rules give numeric remedies that work: the suggested effort covers
the worst gravity torque, the suggested dt and Kd make the explicit PD loop stable."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, cast

import pytest

from armcli.analysis.verdict import round_down
from armcli.check.dynamics import EFFORT_MARGIN, round_up
from armcli.spec.load import load_spec
from tests.check.edited import findings, joint
from tests.helpers import course_gains_spec

G = 9.81  # [m/s²], Pinocchio's default gravity


def test_gravity_effort_remedy_covers_the_torque() -> None:
    def edit(r: Any) -> None:
        joint(r, "arm_base_forearm_joint").find("limit").set("effort", "1")

    (f,) = [f for f in findings(edit) if f.rule == "gravity-effort"]
    # Worst gravity torque on joint 1: both 0.3 kg links horizontal, COMs at 0.15 and 0.45 m.
    torque = 0.3 * G * (0.15 + 0.45)
    assert f.values["gravity_max"] == pytest.approx(torque, rel=1e-9)
    assert f.fix["effort"] == round_up(EFFORT_MARGIN * torque) >= EFFORT_MARGIN * torque
    assert f'effort="{f.fix["effort"]:g}"' in f.message


def test_pd_remedy_is_stable(tmp_path: Path) -> None:
    """The suggested dt and Kd for the course gains must each make the explicit loop stable
    (docs/check.md: stable for dt <= 0.705 ms, or Kd x 0.697 with Kp kept)."""
    course = load_spec(course_gains_spec(tmp_path))  # the course's Kp 50, Kd 5
    (f,) = [f for f in findings(lambda r: None, course) if f.rule == "pd-explicit-unstable"]
    # 0.9 x the bounds, rounded down to 2 digits; Kp kept
    assert f.fix == {"dt": 0.00063, "kp": [50.0, 50.0], "kd": [3.1, 3.1]}
    lam = float(f.values["lambda_max"])  # type: ignore[arg-type]
    kp, damping = float(f.values["kp"]), 0.1  # type: ignore[arg-type]
    kd = float(f.values["kd_plus_damping"]) - damping  # type: ignore[arg-type]
    fixed_kd = max(cast(list[float], f.fix["kd"]))
    for dt, d in ((f.fix["dt"], kd + damping), (cast(float, f.values["dt"]), fixed_kd + damping)):
        # Jury test on the semi-implicit Euler update: a + 2b < 4 (docs/check.md); with
        # equal gains the worst mode is lambda_max's.
        a, b = kp * float(dt) * float(dt) * lam, float(d) * float(dt) * lam  # type: ignore[arg-type]
        assert a + 2 * b < 4, (dt, d)


def test_rounding_helpers() -> None:
    assert round_up(4.3) == 4.3 and round_up(4.31) == 4.4 and round_up(0.0123) == 0.013
    assert round_down(0.000705) == 0.0007 and round_down(3.48) == 3.4
    assert math.isclose(round_up(2.6487), 2.7)
