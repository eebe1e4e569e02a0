"""Fuzz the spec loader: whatever the input, only armcli's own errors may escape."""

from __future__ import annotations

from typing import Any

import yaml
from hypothesis import given
from hypothesis import strategies as st

from armcli.errors import ArmcliError
from armcli.spec.load import loads_spec
from armcli.spec.model import RobotSpec
from tests.helpers import ROOT, mutated

BASE = yaml.safe_load((ROOT / "specs" / "my_robot.yaml").read_text())


def _load(text: str) -> RobotSpec | None:
    try:
        return loads_spec(text, "fuzz.yaml")
    except ArmcliError as exc:
        lines = exc.lines()
        assert lines and all(ln.startswith("fuzz.yaml") for ln in lines), lines
        return None


@given(mutated(BASE))
def test_fuzz_spec_structured(doc: Any) -> None:
    try:
        text = yaml.safe_dump(doc, allow_unicode=True)
    except yaml.YAMLError:
        return
    spec = _load(text)
    if spec is not None:  # accepted specs must be internally consistent
        assert spec.movable_arm_joints() is not None
        for name in spec.poses:
            assert set(spec.pose(name)) >= set(spec.movable_arm_joints())


@given(st.data())
def test_fuzz_spec_text_edits(data: st.DataObject) -> None:
    text = yaml.safe_dump(BASE)
    pos = data.draw(st.integers(0, len(text)))
    cut = data.draw(st.integers(0, 20))
    insert = data.draw(st.text(alphabet=st.characters(codec="utf-8"), max_size=10))
    _load(text[:pos] + insert + text[pos + cut :])
