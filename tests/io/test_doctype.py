"""A DOCTYPE is read from the document's prolog, not searched for in its text (issue 42).

Before: `<!DOCTYPE` anywhere refused the document, comments included, and armcli's own
generated xacro and URDF files name the spec in their header comment: a spec named
`r--><!DOCTYPE robot [...]><!--.yaml` no longer built (the safe expansion refused the
generated xacro), and `check` refused the URDF built from it.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from armcli.io.doctype import doctype_offset
from tests.helpers import DEFAULT_SPEC, run_cli

HOSTILE_NAME = 'r--><!DOCTYPE robot [<!ENTITY x "y">]><!--.yaml'


PROLOG = '\ufeff<?xml version="1.0"?>\n<!-- a -->\n'


@pytest.mark.parametrize(
    ("text", "declared"),
    [
        ('<!DOCTYPE robot [<!ENTITY x "y">]><robot/>', True),
        (PROLOG + '<!DOCTYPE r SYSTEM "file:///etc/passwd"><r/>', True),
        ("<?xml version='1.0'?><?pi <!DOCTYPE ?>\n\t<!-- --><!DOCTYPE r><r/>", True),
        ('<!-- <!DOCTYPE robot [<!ENTITY x "y">]> --><robot/>', False),  # only mentioned
        ('<robot><!-- <!DOCTYPE r> --><a b="&lt;!DOCTYPE"/></robot>', False),
        ("<robot/><!DOCTYPE r>", False),  # after the root: a syntax error, not a DTD
        ("<!-- never closed <!DOCTYPE r>", False),  # the parser refuses it
    ],
)  # fmt: skip
def test_only_a_prolog_doctype_counts(text: str, declared: bool) -> None:
    # in these texts the declaration, when there is one, is the last `<!DOCTYPE`
    assert doctype_offset(text) == (text.rindex("<!DOCTYPE") if declared else None)


def test_a_spec_whose_name_reads_like_a_doctype_builds_and_checks(tmp_path: Path) -> None:
    spec = tmp_path / HOSTILE_NAME
    shutil.copy(DEFAULT_SPEC, spec)
    proc = run_cli(["build", spec, "-o", tmp_path / "out"], tmp_path)
    assert proc.returncode == 0, proc.stderr  # before: "... declares a DOCTYPE/entities"
    built = tmp_path / "out" / "my_robot.urdf"
    assert "<!DOCTYPE" in built.read_text()  # in its header comment, escaped
    proc = run_cli(["check", built], tmp_path)
    assert proc.returncode == 0, proc.stderr  # before: "DOCTYPE/entity declarations ..."


def test_a_real_doctype_is_still_refused_in_urdf_and_xacro(tmp_path: Path) -> None:
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        '<?xml version="1.0"?>\n<!-- x -->\n<!DOCTYPE r [<!ENTITY a "b">]>\n<robot name="r"/>\n'
    )
    proc = run_cli(["check", urdf], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert f"{urdf}:3: DOCTYPE/entity declarations are not allowed" in proc.stderr
    xacro = tmp_path / "r.urdf.xacro"
    xacro.write_text(urdf.read_text())
    proc = run_cli(["expand", xacro], tmp_path)
    assert proc.returncode == 2 and "declares a DOCTYPE/entities" in proc.stderr, proc.stderr
