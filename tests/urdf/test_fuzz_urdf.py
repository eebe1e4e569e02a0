"""Fuzz the URDF reader and the check pipeline: only armcli's own errors may escape.

Mutations start from the committed urdf/my_robot.urdf and change one place at a
time (a hostile attribute value, a deleted attribute or element, a duplicated
element, a renamed tag, a DOCTYPE), so most examples are almost-valid URDFs that
reach the rules and Pinocchio rather than dying in the XML parser.
"""

from __future__ import annotations

import contextlib
import copy
import json

from hypothesis import given
from hypothesis import strategies as st
from lxml import etree

from armcli.check.report import to_json
from armcli.check.rules import RULES
from armcli.check.run import check_urdf
from armcli.errors import ArmcliError
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf
from armcli.urdf.tree import tree_from_urdf
from tests.helpers import ROOT

SOURCE = "fuzz.urdf"
BASE = (ROOT / "urdf" / "my_robot.urdf").read_bytes()
HOSTILE_VALUES = st.one_of(
    st.sampled_from(
        [
            "nan",
            "NaN 0 0",
            "inf",
            "-inf",
            "1e309",
            "-1e-320",
            "0",
            "-0",
            "-1",
            "1e300",
            "",
            " ",
            "0 0",
            "0 0 0 0 0",
            "1_000",
            "0x10",
            "pi",
            "${pi/2}",
            "$(eval 1)",
            "../../etc/passwd",
            "package://../../etc/passwd",
            "file:///etc/passwd",
            "\u00e9\u00e8",
            "a" * 300,
            "fixed",
            "floating",
            "planar",
            "continuous",
            "prismatic",
            "ball",
            "base_footprint",
            "arm_base_link",
            "hand_link",
        ]
    ),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=5).map(
        lambda xs: " ".join(map(repr, xs))
    ),
    st.text(alphabet=st.characters(codec="utf-8", exclude_categories=["Cs", "Cc"]), max_size=12),
)
DOCTYPES = [
    b'<!DOCTYPE robot [<!ENTITY e "x">]>\n',
    b'<!DOCTYPE robot [<!ENTITY e SYSTEM "file:///etc/passwd">]>\n',
    b'<!DOCTYPE robot SYSTEM "robot.dtd">\n',
]


def _elements(root: etree._Element) -> list[etree._Element]:
    return [el for el in root.iter() if isinstance(el.tag, str)]


@st.composite
def mutated_urdf(draw: st.DrawFn, max_mutations: int = 3) -> bytes:
    """my_robot.urdf with 1..max_mutations structured changes, serialised to bytes."""
    root = copy.deepcopy(etree.fromstring(BASE))
    for _ in range(draw(st.integers(1, max_mutations))):
        el = draw(st.sampled_from(_elements(root)))
        action = draw(st.sampled_from(["set", "drop-attr", "drop", "dup", "rename", "nest"]))
        parent = el.getparent()
        if action == "set":
            attrs = [*el.attrib] or ["name"]
            el.set(draw(st.sampled_from(attrs)), draw(HOSTILE_VALUES))
        elif action == "drop-attr" and el.attrib:
            del el.attrib[draw(st.sampled_from(list(el.attrib)))]
        elif action == "drop" and parent is not None:
            parent.remove(el)
        elif action == "dup" and parent is not None:
            parent.append(copy.deepcopy(el))
        elif action == "rename":
            el.tag = draw(st.sampled_from(["link", "joint", "robot", "visual", "mesh", "origin"]))
        elif action == "nest" and parent is not None:
            wrapper = etree.Element(draw(st.sampled_from(["link", "geometry", "inertial"])))
            parent.replace(el, wrapper)
            wrapper.append(el)
    data = etree.tostring(root, encoding="utf-8", xml_declaration=True)
    if draw(st.integers(0, 19)) == 0:  # now and then a DOCTYPE after the declaration
        head, _, rest = data.partition(b"?>")
        data = head + b"?>\n" + draw(st.sampled_from(DOCTYPES)) + rest
    return data


def _parse(data: bytes) -> Urdf | None:
    try:
        return parse_urdf(data, SOURCE)
    except ArmcliError as exc:
        lines = exc.lines()
        assert lines and all(ln.startswith(SOURCE) for ln in lines), lines
        return None


def _check(urdf: Urdf) -> None:
    """The check pipeline's library API and its JSON report: findings, never crashes."""
    try:
        result = check_urdf(urdf)
    except ArmcliError:
        return
    for f in result.findings:
        assert f.rule in RULES and f.file == SOURCE and f.message, f
    json.loads(to_json([result], list(result.findings), 1))  # strict JSON: no NaN leaks


@given(mutated_urdf())
def test_fuzz_urdf_structured(data: bytes) -> None:
    urdf = _parse(data)
    if urdf is None:
        return
    with contextlib.suppress(ArmcliError):
        tree_from_urdf(urdf)  # what view/render/tree use
    _check(urdf)


@given(st.data())
def test_fuzz_urdf_text_edits(data: st.DataObject) -> None:
    """Byte-level edits (cuts, insertions) of the valid file: the XML layer must hold."""
    pos = data.draw(st.integers(0, len(BASE)))
    cut = data.draw(st.integers(0, 40))
    insert = data.draw(st.binary(max_size=12) | st.sampled_from([b"<", b"&e;", b"<!--", b'"']))
    urdf = _parse(BASE[:pos] + insert + BASE[pos + cut :])
    if urdf is not None:
        _check(urdf)


def test_absurd_mass_is_checked_without_overflow() -> None:
    """Found by the fuzz profile: a mass of 6.48e156 kg overflowed the inertia comparison's norm
    (a RuntimeWarning, an error under pytest); inertia.relative_difference now rescales."""
    data = BASE.replace(b'<mass value="0.5"/>', b'<mass value="1e300"/>', 1)
    assert data != BASE
    urdf = _parse(data)
    assert urdf is not None
    _check(urdf)
