"""docs/spec.md is generated from the models: it must match, and every field must say what it is."""

from __future__ import annotations

import re

from armcli.spec.model import RobotSpec
from armcli.spec.reference import spec_reference
from tests.helpers import ROOT

UNIT = re.compile(r"\[[^\]]+\]")  # a unit in brackets, such as [m] or [N·m or N]


def test_docs_spec_md_is_up_to_date() -> None:
    committed = (ROOT / "docs" / "spec.md").read_text()
    assert committed == spec_reference(), "run: python -m armcli.spec.reference > docs/spec.md"


def test_every_field_is_described_and_numbers_carry_units() -> None:
    text = spec_reference()
    rows = [r for r in text.splitlines() if r.startswith("| `")]
    assert len(rows) > 60
    for row in rows:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert cells[-1], f"no description: {row}"
        if cells[1] == "float" and "[0, 1]" not in cells[-1]:
            assert UNIT.search(cells[-1]), f"a number without a unit: {row}"
    assert "## RobotSpec" in text and RobotSpec.__name__ in text
