"""`simulate --urdf` refuses what `check` calls an error in the dynamics, and only that."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from armcli.check import run
from armcli.check.context import URDF
from armcli.check.gate import NOT_SIMULATED, bears_on_balance, refuse_check_errors, require_known
from armcli.check.rules import ERROR, RULES
from armcli.check.run import check_urdf, families_for
from armcli.errors import InputError, ModelRefusedError
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf
from tests.helpers import ROOT

ARM = (ROOT / "urdf" / "standalone_arm.urdf").read_text()


def test_the_course_arm_passes() -> None:
    refuse_check_errors(parse_urdf(ARM.encode(), "standalone_arm.urdf"))


def test_a_zero_axis_is_refused_with_checks_rule_id() -> None:
    bad = ARM.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>', 1)
    assert bad != ARM
    with pytest.raises(ModelRefusedError) as exc:
        refuse_check_errors(parse_urdf(bad.encode(), "zero_axis.urdf"))
    assert "axis" in str(exc.value)


def test_a_missing_mesh_does_not_block_the_simulation() -> None:
    """Meshes never enter the dynamics: a mesh-missing error is check's, not simulate's."""
    tail = "</visual>"
    assert tail in ARM
    head, rest = ARM.split("<visual>", 1)
    _body, after = rest.split(tail, 1)
    meshy = (
        head
        + '<visual><geometry><mesh filename="package://nowhere/m.stl"/></geometry>'
        + tail
        + after
    )
    assert "mesh-missing" in NOT_SIMULATED
    refuse_check_errors(parse_urdf(meshy.encode(), "meshy.urdf"))


# The gate runs only the rule families that can refuse (check.run.check_rules); the full
# check is its reference: the same refusals, rule, line and message, on robots that break
# each kind of rule. Edits of the course robot, one refusal kind each:
MY = (ROOT / "urdf" / "my_robot.urdf").read_text()
EDITS = {
    "zero-axis": ('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>'),  # axis: blocks the balance
    "negative-mass": ('<mass value="1"/>', '<mass value="-1"/>'),  # mass-nonpositive
    "triangle": ('ixx="0.002708333333333334"', 'ixx="0.02"'),  # inertia-triangle: dynamics
    "heavy-hand": ('<mass value="0.5"/>', '<mass value="50"/>'),  # gravity-effort: not refused
    "unknown-child": ('<child link="', '<child link="no_'),  # blocks the model
}
ROBOTS = [
    *(parse_urdf(MY.replace(*e, 1).encode(), f"{k}.urdf") for k, e in EDITS.items()),
    *(parse_urdf(p.read_bytes(), p.name) for p in sorted((ROOT / "urdf").glob("*.urdf"))),
    *(
        parse_urdf(p.read_bytes(), p.name)
        for p in sorted((ROOT / "tests" / "fixtures").rglob("*.urdf"))
        if "meshes" not in p.parts
    ),
]
ONLY: dict[str, Callable[[str], bool] | None] = {"all": None, "balance": bears_on_balance}


def _refused(urdf: Urdf, ignore: tuple[str, ...], only: Callable[[str], bool] | None) -> list:
    try:
        refuse_check_errors(urdf, ignore=ignore, only=only)
    except ModelRefusedError as exc:
        return [(v.rule, v.line, v.message) for v in exc.violations]
    return []


@pytest.mark.parametrize("only", ONLY, ids=list(ONLY))
def test_the_gate_refuses_what_the_full_check_calls_a_refusing_error(only: str) -> None:
    keep = ONLY[only]
    refused = set()
    for urdf in ROBOTS:
        for ignore in ((), ("axis", "pd-unstable", "com-outside-support")):
            skip = NOT_SIMULATED | set(ignore)
            reference = [
                (f.rule, f.line, f.message)
                for f in check_urdf(urdf).findings
                if f.severity == ERROR and f.rule not in skip and (keep is None or keep(f.rule))
            ]
            assert _refused(urdf, ignore, keep) == reference, (urdf.source, ignore)
            if reference and not ignore:
                refused.add(urdf.source)
    # not vacuous: the edits that break what the balance reads are refused by both gates
    assert {"zero-axis.urdf", "negative-mass.urdf", "unknown-child.urdf"} <= refused, refused
    if keep is None:  # and the dynamics' and the sensors' errors by the run's own gate
        assert {"triangle.urdf", "sensor_link.urdf"} <= refused, refused
    else:
        assert "sensor_link.urdf" not in refused


def test_the_balance_gate_skips_the_dynamics_and_the_sensors() -> None:
    refusing = {r for r, rule in RULES.items() if rule.severity == ERROR}
    everything = {f.name for f in families_for(lambda r: r in refusing - NOT_SIMULATED)}
    balance = {f.name for f in families_for(lambda r: r in refusing and bears_on_balance(r))}
    assert {"stability", "servo", "sensors", "reach"} <= everything - balance
    # never asked: a mesh, the gravity load and self-collision do not refuse a run
    assert not {"meshes", "gravity", "self-collision"} & everything


def test_a_family_reports_only_the_rules_it_declares(monkeypatch: pytest.MonkeyPatch) -> None:
    """An undeclared rule would escape a gate that asks for it: Collector refuses it."""
    stray = run.Family("stray", URDF, lambda c: c.out.add("axis", None, "x"), frozenset())
    monkeypatch.setattr(run, "FAMILIES", (*run.FAMILIES, stray))
    with pytest.raises(RuntimeError, match="'axis' is not among the rules"):
        check_urdf(parse_urdf(MY.encode(), "my_robot.urdf"))
    assert all(f.rules <= set(RULES) for f in run.FAMILIES[:-1])  # every id is a real rule


def test_an_unknown_rule_to_ignore_is_refused_by_its_field() -> None:
    with pytest.raises(InputError) as err:
        require_known(["axis", "no-such-rule"])
    assert err.value.field == "ignore" and "no-such-rule" in str(err.value)
    require_known(["axis", "pd-unstable"])  # real rules pass
