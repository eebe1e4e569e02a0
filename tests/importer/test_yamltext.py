"""The imported spec's numbers read back as exactly the URDF's floats; text stays readable."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from armcli.importer.yamltext import Block, BlockMap, Num, document, number, pi_fraction
from armcli.io.yaml import loads_yaml
from armcli.spec.expr import eval_expr


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (math.pi / 2, "pi/2"),
        (-math.pi / 2, "-pi/2"),
        (3 * math.pi / 4, "3*pi/4"),
        (2 * math.pi, "2*pi"),
        (math.pi, "pi"),
        (1.5708, "1.5708"),  # not pi/2: written as the URDF wrote it
        (1.570796325, "1.570796325"),  # UR's rounded pi/2 is not pi/2 either
        (0.1, "0.1"),
        (1e-05, "1e-05"),
        (-0.0, "0"),
        (100.0, "100"),
    ],
)
def test_numbers_are_pi_fractions_only_when_exact(value: float, text: str) -> None:
    assert number(value) == text
    assert eval_expr(text) == value  # the spec's own parser gives the float back exactly


@given(st.floats(allow_nan=False, allow_infinity=False, width=64))
def test_every_float_reads_back_exactly(value: float) -> None:
    doc = loads_yaml(document({"v": [Num(value)]}))
    read = doc.data["v"][0]
    assert (eval_expr(read) if isinstance(read, str) else float(read)) == value


def test_pi_fraction_refuses_near_misses() -> None:
    assert pi_fraction(math.pi / 2 + 1e-15) is None
    assert pi_fraction(0.0) is None


def test_strings_that_yaml_would_misread_are_quoted() -> None:
    data = {"a": "yes", "b": "package://p/m.stl", "c": "12", "d": "joint_0.0", "e": "Gazebo/Grey"}
    text = document(data)
    assert loads_yaml(text).data == data
    assert "d: joint_0.0" in text and "e: Gazebo/Grey" in text  # plain where that is safe


def test_layout_flow_leaves_blocks_for_long_and_marked_mappings() -> None:
    data = {
        "origin": {"xyz": [Num(0.1), 0, 0]},
        "gains": BlockMap(j1=BlockMap(kp=Num(1.0), kd=Num(0.5))),
        "xml": [Block("<a>\n  <b/>\n</a>")],
    }
    text = document(data, header=["from x.urdf"])
    assert text.splitlines()[:2] == ["# from x.urdf", "origin: {xyz: [0.1, 0, 0]}"]
    assert "gains:\n  j1:\n    kp: 1\n    kd: 0.5" in text
    assert loads_yaml(text).data["xml"] == ["<a>\n  <b/>\n</a>\n"]
