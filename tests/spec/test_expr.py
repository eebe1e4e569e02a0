"""Angle expressions: values against math.pi, and anything beyond arithmetic refused."""

from __future__ import annotations

import math

import pytest

from armcli.spec.expr import eval_expr


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("pi/2", math.pi / 2),
        ("-pi/4", -math.pi / 4),
        ("3*pi/4", 3 * math.pi / 4),
        ("0.5", 0.5),
        ("2 * (pi - 1)", 2 * (math.pi - 1)),
        ("+1e-3", 1e-3),
    ],
)
def test_values(text: str, expected: float) -> None:
    assert eval_expr(text) == pytest.approx(expected, rel=0, abs=0)


@pytest.mark.parametrize(
    "text",
    [
        "__import__('os').system('true')",
        "pi ** 2",
        "e",
        "1/0",
        "",
        "1e400",
        "[1]",
        "pi.real",
        "x" * 100,
    ],
)
def test_refused(text: str) -> None:
    with pytest.raises(ValueError):
        eval_expr(text)
