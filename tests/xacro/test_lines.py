"""Where each expanded element was written (xacro_lines), through includes and nested macros.

References: the line numbers are found by searching the fixture text; the expansion must
stay byte for byte what xacro itself writes (xacro run in this process on our own file).
"""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from armcli.urdf.source import allowed_roots
from armcli.xacro.args import XacroInputs
from armcli.xacro.lines import Origin, parse_map
from armcli.xacro.safe import expand_safe_report
from tests.helpers import FIXTURES

TOP = FIXTURES / "real_robots" / "xacro_lines" / "robot.urdf.xacro"
NESTED = """<?xml version="1.0"?>
<robot name="nested" xmlns:xacro="http://ros.org/wiki/xacro">
  <xacro:macro name="inner" params="n">
    <link name="${n}_link"/>
  </xacro:macro>
  <xacro:macro name="outer" params="n">
    <xacro:inner n="${n}"/>
  </xacro:macro>
  <link name="root"/>
  <xacro:outer n="a"/>
</robot>
"""


def _line(text: str, needle: str) -> int:
    (k,) = [i for i, row in enumerate(text.splitlines(), 1) if needle in row]
    return k


def _expand(path: Path) -> tuple[bytes, dict[int, Origin]]:
    out, used = expand_safe_report(path, allowed_roots(path.parent), XacroInputs())
    return out, parse_map(used.source_map)


def test_an_included_macros_element_points_at_its_own_file_and_the_call() -> None:
    import xacro

    out, origins = _expand(TOP)
    # The positions are taken out again: the bytes are xacro's own.
    assert out == xacro.process_file(str(TOP)).toprettyxml(indent="  ", encoding="utf-8")
    root = etree.fromstring(out)
    (inertia,) = root.iterfind("link[@name='back_caster_link']/inertial/inertia")
    o = origins[inertia.sourceline]
    parts = TOP.parent / "parts" / "caster.xacro"
    assert (o.file, o.line) == (str(parts), _line(parts.read_text(), "<inertia ixx"))
    assert o.calls == ((str(TOP), _line(TOP.read_text(), "<xacro:caster ")),)
    # An element written in the top file itself: its own line, no call.
    (base,) = root.iterfind("link[@name='base_link']")
    assert origins[base.sourceline] == Origin(str(TOP), _line(TOP.read_text(), '"base_link">'))


def test_nested_macro_calls_are_listed_innermost_first(tmp_path: Path) -> None:
    path = tmp_path / "nested.urdf.xacro"
    path.write_text(NESTED)
    out, origins = _expand(path)
    (link,) = etree.fromstring(out).iterfind("link[@name='a_link']")
    o = origins[link.sourceline]
    assert o.line == _line(NESTED, "${n}_link")
    assert o.calls == ((str(path), _line(NESTED, '<xacro:inner n="${n}"')),
                       (str(path), _line(NESTED, '<xacro:outer n="a"')))  # fmt: skip
