"""One stability story (issue 23): `check`'s verdicts, remedies and `simulate`'s refusal agree.

Property test over random gains, time steps, joint damping, link inertia and gravity
compensation on the course arm: every remedy `check` writes, applied, passes `check` for
its loop and `simulate`'s acceptance; `simulate` refuses exactly when `check` reports
`pd-unstable` and suggests the same numbers; no suggestion is negative, and no verdict
contradicts its own bounds. `simulate` is given `check`'s operating points (the joint-space
grid), so both judge the same configurations.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.errors import UnstableLoopError
from armcli.robot import sampling
from armcli.robot.model import Robot
from armcli.sim.simulate import SimConfig, check_stability, simulated
from armcli.spec.load import load_spec
from armcli.spec.model import Gains, RobotSpec
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf
from tests.helpers import DEFAULT_SPEC, ROOT

ARM = (ROOT / "urdf" / "standalone_arm.urdf").read_text()
SPEC = load_spec(DEFAULT_SPEC)
JOINTS = ("arm_base_forearm_joint", "forearm_hand_joint")
RULES = ("pd-unstable", "pd-explicit-unstable")
EDGE_RTOL = 1e-6  # examples this close to a loop's edge are skipped (rounding decides them)
EXAMPLES = 40


def _urdf(mass_scale: float, damping: float) -> Urdf:
    """The course arm with every mass and inertia scaled and the joint damping replaced."""
    text = re.sub(r'(<mass value=")([^"]+)"', lambda m: f'{m[1]}{float(m[2]) * mass_scale!r}"', ARM)
    text = re.sub(r'( i[xyz]{2}=")([^"]+)"', lambda m: f'{m[1]}{float(m[2]) * mass_scale!r}"', text)
    text = text.replace('damping="0.1"', f'damping="{damping!r}"')
    return parse_urdf(text.encode(), "standalone_arm.urdf")


def _spec(kp: list[float], kd: list[float], dt: float, gc: bool) -> RobotSpec:
    gains = {j: Gains(kp=p, kd=d) for j, p, d in zip(JOINTS, kp, kd, strict=True)}
    control = SPEC.control.model_copy(update={"dt": dt, "gravity_compensation": gc, "gains": gains})
    return SPEC.model_copy(update={"control": control, "poses": {}})


def _check(urdf: Urdf, kp: list[float], kd: list[float], dt: float, gc: bool) -> Any:
    return check_urdf(urdf, CheckOptions(spec=_spec(kp, kd, dt, gc)))


def _simulate_accepts(urdf: Urdf, kp: list[float], kd: list[float], dt: float,
                      gc: bool) -> UnstableLoopError | None:  # fmt: skip
    """`simulate`'s refusal on check's own operating points (None: accepted)."""
    robot = Robot.load(urdf, strict=False)
    arm = simulated(robot)
    configs = np.array([[p[j] for j in arm.names] for p, _ in sampling.configurations(robot)])
    cfg = SimConfig(np.array(kp, dtype=float), np.array(kd, dtype=float), dt, gravity_comp=gc)
    try:
        check_stability(arm, cfg, configs)
    except UnstableLoopError as exc:
        return exc
    return None


def _no_contradiction(v: Any, dt: float) -> None:
    """A verdict agrees with its own bounds: stable iff dt <= dt_max iff gain factor >= 1."""
    assume(abs(dt / v.dt_max - 1.0) > EDGE_RTOL if math.isfinite(v.dt_max) else True)
    assert v.stable == (dt <= v.dt_max)
    if v.gain_scale is not None:
        assume(abs(v.gain_scale - 1.0) > EDGE_RTOL)
        assert v.stable == (v.gain_scale >= 1.0)
    assert v.dt_max > 0.0 and (v.gain_scale is None or v.gain_scale > 0.0)


positive = st.floats(min_value=0.0, max_value=0.0) | st.floats(1e-3, 1e2)


@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    kp=st.lists(st.floats(1.0, 1e6), min_size=2, max_size=2),
    kd=st.lists(positive, min_size=2, max_size=2),
    dt=st.floats(1e-4, 2e-2),
    damping=st.sampled_from([0.0, 0.01, 0.1, 1.0]),
    mass_scale=st.floats(0.05, 20.0),
    gc=st.booleans(),
)
def test_every_suggestion_applied_passes_check_and_simulate(
    kp: list[float], kd: list[float], dt: float, damping: float, mass_scale: float, gc: bool
) -> None:
    urdf = _urdf(mass_scale, damping)
    result = _check(urdf, kp, kd, dt, gc)
    st_ = result.summary.stability
    assert st_ is not None
    _no_contradiction(st_.implicit, dt)
    _no_contradiction(st_.explicit, dt)
    found = {f.rule: f for f in result.findings if f.rule in RULES}
    assert ("pd-unstable" in found) == (not st_.implicit.stable)
    assert ("pd-explicit-unstable" in found) == (not st_.explicit.stable)
    refusal = _simulate_accepts(urdf, kp, kd, dt, gc)
    assert (refusal is not None) == ("pd-unstable" in found)  # one bound, one verdict
    for rule, f in found.items():
        fix = f.fix
        assert not re.search(r"(dt|Kp|Kd|kp|kd) (<=?|=) -", f.message)  # never negative
        assert 0.0 < fix["dt"] < dt
        attempts = [(kp, kd, float(fix["dt"]))]
        if "kp" in fix:
            new_kp, new_kd = list(fix["kp"]), list(fix["kd"])
            assert all(0.0 <= a <= b for a, b in zip(new_kp, kp, strict=True))
            assert all(0.0 <= a <= b for a, b in zip(new_kd, kd, strict=True))
            attempts.append((new_kp, new_kd, dt))
        if rule == "pd-unstable":  # simulate suggests what check writes
            assert refusal is not None and refusal.suggestion_dt == fix["dt"]
            assert refusal.kp == (tuple(fix["kp"]) if "kp" in fix else None)
        for a_kp, a_kd, a_dt in attempts:
            again = {g.rule for g in _check(urdf, a_kp, a_kd, a_dt, gc).findings}
            cleared = {"pd-unstable", "pd-explicit-unstable"} if rule != "pd-unstable" else {rule}
            assert not (again & cleared), (rule, a_kp, a_kd, a_dt)
            assert _simulate_accepts(urdf, a_kp, a_kd, a_dt, gc) is None


def test_the_issues_kp_50000_case_reads_as_one_story() -> None:
    """Issue 23: kp = 50000 suggested "Kd < -21.5", said "stable; Kp < 1.742e+04" and
    scaled gains differently in check and simulate."""
    urdf = _urdf(1.0, 0.1)
    result = _check(urdf, [5e4, 5e4], [5.0, 5.0], 1e-3, False)
    found = {f.rule: f for f in result.findings if f.rule in RULES}
    assert set(found) == set(RULES)
    implicit = found["pd-unstable"]
    assert implicit.message.startswith("armcli simulate (damping implicit) diverges")
    assert found["pd-explicit-unstable"].message.startswith("explicit torque loop")
    assert "Kd < -" not in found["pd-explicit-unstable"].message
    refusal = _simulate_accepts(urdf, [5e4, 5e4], [5.0, 5.0], 1e-3, False)
    assert refusal is not None and refusal.kp == tuple(implicit.fix["kp"])
    kp_max = result.summary.stability.kp_max_implicit
    assert kp_max is not None and kp_max < 5e4  # the bound it prints is below the gains


@pytest.mark.parametrize("gc", [False, True])
def test_seed_gains_verdicts(gc: bool) -> None:
    """The course gains: simulate's loop stable, the explicit loop not (brief: Kd 5 at 1 ms)."""
    result = _check(_urdf(1.0, 0.1), [50.0, 50.0], [5.0, 5.0], 1e-3, gc)
    assert {f.rule for f in result.findings if f.rule in RULES} == {"pd-explicit-unstable"}
