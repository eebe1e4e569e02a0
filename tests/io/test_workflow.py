"""`armcli expand` never prints a line GitHub reads as a workflow command (issue 42).

Before: a text node holding `&#10;::error::...` (or an attribute, CDATA section, comment or
processing instruction with a line break before `::`) came out as a line of its own, which
GitHub Actions reads as a command (it trims leading white space). The reference for "parses
as it did" is lxml reading xacro's own output next to armcli's.
"""

from __future__ import annotations

import re
from pathlib import Path

from lxml import etree

from armcli.io.workflow import no_workflow_commands
from tests.helpers import ROOT, run_cli

HOSTILE = (
    '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
    '<link name="l&#10;  ::error::attribute"/>\n'
    "<gazebo>a&#10;::error::text&#13;::add-mask::x&#10;\t::stop-commands::y</gazebo>\n"
    "<plugin><![CDATA[x\n::error::cdata]]></plugin>\n"
    "<!--\n::warning::comment\n-->\n"
    "<?pi x\n::notice::pi?>\n"
    "</robot>\n"
)


def commands(text: str) -> list[str]:
    """The lines GitHub reads as workflow commands: split at CR, LF, CRLF; left-trimmed."""
    return [ln for ln in re.split(r"\r\n|\r|\n", text) if ln.lstrip().startswith("::")]


def test_expand_prints_no_workflow_command(tmp_path: Path) -> None:
    src = tmp_path / "w.urdf.xacro"
    src.write_text(HOSTILE)
    out = tmp_path / "w.urdf"
    printed = run_cli(["expand", src], tmp_path)
    written = run_cli(["expand", src, "-o", out], tmp_path)
    assert printed.returncode == written.returncode == 0, printed.stderr + written.stderr
    assert commands(printed.stdout) == [] and commands(printed.stderr) == []
    assert out.read_text() == printed.stdout  # the same document either way
    from armcli.urdf.source import expand_xacro

    raw = etree.fromstring(expand_xacro(src)[0])  # xacro's own bytes, lines and all
    doc = etree.fromstring(out.read_bytes())
    assert doc.find("plugin").text == raw.find("plugin").text  # CDATA, pretty-printed
    assert doc.find("link").get("name") == raw.find("link").get("name")  # normalised
    # a text's CR is kept (a raw CR would be read as LF): the value the source file gave
    assert doc.find("gazebo").text == "a\n::error::text\r::add-mask::x\n\t::stop-commands::y"


def test_a_document_without_such_lines_is_left_byte_for_byte(tmp_path: Path) -> None:
    proc = run_cli(["expand", ROOT / "urdf" / "my_robot.urdf.xacro"], tmp_path)
    assert proc.returncode == 0, proc.stderr
    data = proc.stdout.encode("utf-8")
    assert no_workflow_commands(data) is data


def test_the_rewrite_parses_as_the_raw_text_does() -> None:
    """Each rewritten place reads the same to an XML parser as xacro's raw output."""
    raw = (
        b'<r a="x\n::error::a"><t>y\n  ::error::t</t><![CDATA[z\n::error::c]]>'
        b"<!-- c\n::error::c --></r>"
    )
    safe = no_workflow_commands(raw)
    assert commands(safe.decode()) == []
    a, b = etree.fromstring(raw), etree.fromstring(safe)
    assert a.get("a") == b.get("a") == "x ::error::a"
    assert a.find("t").text == b.find("t").text == "y\n  ::error::t"
    assert a.find("t").tail == b.find("t").tail == "z\n::error::c"
