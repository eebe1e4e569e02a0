"""Joint rules: `limit-degrees` on both sides as docs/check.md documents it (multi-turn
ranges and sentinels left alone), and a limit without bounds as `missing-limit` only."""

from __future__ import annotations

from typing import Any

import pytest

from tests.check.edited import findings, joint


def limits(lower: str, upper: str) -> Any:
    def edit(r: Any) -> None:
        lim = joint(r).find("limit")
        lim.set("lower", lower)
        lim.set("upper", upper)

    return edit


@pytest.mark.parametrize(
    ("lower", "upper", "fires"),
    [
        ("-10", "10", False),  # solo/bolt multi-turn range, docs/check.md: left alone
        ("-9.42477796", "9.42477796", False),  # 3 pi
        ("-1e16", "1e16", False),  # "unlimited" sentinel
        ("0", "15", True),  # the smallest round degree value flagged
        ("-90", "90", True),  # degrees typed as radians
        ("0", "360", True),
        ("0", "725", False),  # beyond 720: a sentinel, not degrees
    ],
)
def test_limit_degrees_both_sides(lower: str, upper: str, fires: bool) -> None:
    rules = {f.rule for f in findings(limits(lower, upper))}
    assert ("limit-degrees" in rules) is fires, rules


def test_limit_without_bounds_is_missing_limit_only() -> None:
    def edit(r: Any) -> None:
        lim = joint(r).find("limit")
        del lim.attrib["lower"]
        del lim.attrib["upper"]

    fs = findings(edit)
    assert [f.rule for f in fs] == ["missing-limit"]
    assert "lower, upper" in fs[0].message
