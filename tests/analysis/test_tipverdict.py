"""One tip-over verdict for both engines: the fixed-base ZMP report and the drive's tilt.

The box-on-feet fixture (tests/fixtures/tipover/box_rod.urdf) tipped both ways: its
zero-moment point held 10 mm past the rear feet long enough to rotate it over
(tests/analysis/test_excursion.py's bound: 0.049 m·s), and its base pitched past the front
edge's tipping angle and left there (tests/analysis/test_liftoff.py). A caller holding
either as a `TipVerdict` prints the same things and ends with the same error type.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis.excursion import excursions
from armcli.analysis.liftoff import verdict
from armcli.analysis.stance import Stance, stance_of
from armcli.analysis.tipverdict import TipVerdict
from armcli.errors import TipOverError
from armcli.sim.tipping import ZmpReport
from armcli.urdf.read import parse_urdf
from tests.analysis.test_excursion import steady
from tests.helpers import FIXTURES

FEET = ("foot_fl", "foot_fr", "foot_rl", "foot_rr")
H = 1.1 / 6.0  # [m] the box's centre of mass height (test_liftoff)


@pytest.fixture(scope="module")
def stance() -> Stance:
    urdf = parse_urdf((FIXTURES / "tipover" / "box_rod.urdf").read_bytes(), "box_rod.urdf")
    found = stance_of(urdf, declared=FEET)
    assert isinstance(found, Stance)
    return found


def _zmp(stance: Stance, seconds: float) -> ZmpReport:
    """The report of the point held 10 mm behind the rear feet for `seconds`."""
    found = excursions(stance, steady(stance, seconds, 0.01))
    return ZmpReport(
        base_accel=(0.21 * 9.81 / H),
        accel_source="--base-accel",
        payload=None,
        threshold=0.02,
        min_margin=-0.01,
        time=0.0,
        case="accelerating",
        direction="rear",
        zmp=(-0.21, 0.0),
        arm_margin=0.2,
        max_base_accel=9.81 * 0.2 / H,
        max_base_accel_margin=9.81 * 0.18 / H,
        impacts=0,
        excursions=found,
    )


def _tilt(stance: Stance, fall: bool) -> TipVerdict:
    """The drive's verdict of a pitch past the front edge that rocks back, or stays over."""
    t = np.linspace(0.0, 2.0, 201)
    front = math.atan2(0.2, H)  # the front edge's tipping angle
    rock = np.where(t < 1.0, (front + 0.1) * np.sin(np.pi * t), 0.0)
    pitch = np.where(t < 1.0, rock, front + 0.5) if fall else rock
    quat = np.column_stack([np.cos(pitch / 2), 0 * pitch, np.sin(pitch / 2), 0 * pitch])
    return verdict(stance, {"swing": 0.0}, t, quat, {})


def _said(v: TipVerdict) -> tuple[list[str], str, TipOverError | None]:
    """What a command prints of any verdict, and the error it ends with."""
    return v.notes(), v.line(), (v.error() if v.tips else None)


def test_both_engines_tip_the_box_through_one_type(stance: Stance) -> None:
    zmp_notes, zmp_line, zmp_error = _said(_zmp(stance, 6.0))  # 0.06 m·s > 0.049: tips
    tilt_notes, tilt_line, tilt_error = _said(_tilt(stance, fall=True))
    assert zmp_line.startswith("zero-moment point") and "TIPS" in zmp_line
    assert tilt_line.startswith("TIPS OVER")
    assert isinstance(zmp_error, TipOverError) and isinstance(tilt_error, TipOverError)
    assert zmp_error.time == pytest.approx(0.0, abs=1e-9)  # the point was outside from t = 0
    assert zmp_error.margin == pytest.approx(-0.01, abs=1e-9)  # 10 mm outside
    assert tilt_error.time == pytest.approx(1.0, abs=0.01)  # it stayed over from t = 1 s
    assert "rear" in str(zmp_error) and "front" in str(tilt_error)
    assert len(tilt_notes) == 1  # the first swing rocked back before the fall
    assert not [n for n in zmp_notes if "does not tip" not in n]


def test_neither_engine_tips_a_box_that_comes_back(stance: Stance) -> None:
    zmp_notes, zmp_line, zmp_error = _said(_zmp(stance, 1.0))  # 0.01 m·s: a wheel lifts
    tilt_notes, tilt_line, tilt_error = _said(_tilt(stance, fall=False))
    assert zmp_error is None and tilt_error is None
    assert "a wheel lifts off, no tip" in zmp_line and "stays upright" in tilt_line
    assert len(zmp_notes) == 2 and all("does not tip" in n for n in zmp_notes)  # both cases
    assert len(tilt_notes) == 1 and "came back" in tilt_notes[0]
