"""The rule registry of `check`: families run in order, each once its stage is there."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from armcli.check import run
from armcli.check.context import (
    BLOCKS_DYNAMICS,
    BLOCKS_MODEL,
    DYNAMICS,
    MODEL,
    URDF,
    Context,
    Stage,
)
from armcli.check.options import CheckOptions
from armcli.check.rules import ERROR, RULES
from armcli.urdf.read import parse_urdf, read_urdf
from tests.helpers import ROOT

GOOD = ROOT / "urdf" / "my_robot.urdf"


def _record(monkeypatch: pytest.MonkeyPatch) -> list[tuple[str, bool]]:
    """Add one family per stage (as a new rule module would) that records its call."""
    seen: list[tuple[str, bool]] = []

    def probe(stage: Stage) -> Callable[[Context], None]:
        return lambda c: seen.append((stage, c.robot is not None))

    extra = tuple(run.Family(f"probe-{s}", s, probe(s)) for s in (DYNAMICS, MODEL, URDF))
    monkeypatch.setattr(run, "FAMILIES", run.FAMILIES + extra)
    return seen


def test_a_new_family_is_one_line_in_the_registry(monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _record(monkeypatch)
    run.check_urdf(read_urdf(GOOD))
    # the document's families first, then the model's in registry order, each with the model
    assert seen == [(URDF, False), (DYNAMICS, True), (MODEL, True)]


def test_a_blocking_error_skips_the_families_that_need_the_model(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen = _record(monkeypatch)
    broken = GOOD.read_bytes().replace(b'<robot name="my_robot"', b'<robot name=""', 1)
    result = run.check_urdf(parse_urdf(broken, "nameless.urdf"))
    assert "robot-name" in {f.rule for f in result.findings}
    assert seen == [(URDF, False)]
    assert result.summary is not None and "model checks skipped" in result.summary.notes[0]


def test_a_dynamics_blocker_keeps_the_model_families(monkeypatch: pytest.MonkeyPatch) -> None:
    seen = _record(monkeypatch)
    broken = GOOD.read_bytes().replace(b'<mass value="0.3"', b'<mass value="-0.3"', 1)
    result = run.check_urdf(parse_urdf(broken, "negative.urdf"), CheckOptions())
    assert "mass-nonpositive" in {f.rule for f in result.findings}
    assert seen == [(URDF, False), (MODEL, True)]


def test_only_error_rules_block_and_dynamics_includes_the_model_blockers() -> None:
    assert BLOCKS_MODEL < BLOCKS_DYNAMICS
    assert all(RULES[r].severity == ERROR for r in BLOCKS_DYNAMICS)
