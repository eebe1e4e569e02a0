"""`armcli import` of hostile URDFs: nothing in the file becomes xacro or YAML (issue 27).

xacro acts on the literal tag `xacro:include` whatever URI the prefix is bound to, so
"is this xacro" is decided by the namespace URI *and* the `xacro` prefix; such a file
is a xacro (expanded in safe mode), and no xacro element is ever kept as passthrough.
A file name holding a newline must not add lines or keys to the spec it writes.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from armcli.errors import InputError, XacroRefusedError
from armcli.importer.file import import_file
from armcli.importer.run import import_urdf
from armcli.spec.load import load_spec
from tests.helpers import FIXTURES

BASE = (FIXTURES / "import" / "sensor_base.urdf").read_text()


def _with(extra: str, *, robot_attrs: str = "") -> str:
    return BASE.replace(
        '<robot name="sensor_base">', f'<robot name="sensor_base"{robot_attrs}>\n{extra}', 1
    )


@pytest.mark.parametrize(
    "extra",
    [
        '<gazebo xmlns:xacro="urn:anything"><xacro:include filename="{secret}"/></gazebo>',
        '<gazebo xmlns:q="http://www.ros.org/wiki/xacro"><q:include filename="{secret}"/></gazebo>',
        '<gazebo xmlns:q="http://www.ros.org/wiki/xacro" q:name="x"/>',
        '<gazebo xmlns:xacro="urn:x"><g xacro:name="link"/></gazebo>',
    ],
    ids=["xacro prefix, other URI", "xacro URI, other prefix", "xacro attribute", "prefixed attr"],
)
def test_xacro_elements_make_the_file_a_xacro(extra: str, tmp_path: Path) -> None:
    secret = tmp_path / "secret" / "s.xml"
    secret.parent.mkdir()
    secret.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><leak/></robot>')
    text = _with(extra.format(secret=secret))
    with pytest.raises(XacroRefusedError):  # import_urdf reads URDF only: refused as xacro
        import_urdf(text.encode(), "r.urdf", tmp_path / "r.yaml")
    src = tmp_path / "pkg" / "r.urdf"
    src.parent.mkdir()
    src.write_text(text)
    out = tmp_path / "r.yaml"
    try:  # as a file: expanded in safe mode, where the include outside the roots is refused
        import_file(src, out)
    except InputError as exc:
        assert "outside the allowed directories" in str(exc) or "xacro" in str(exc)
        assert not out.exists()
        return
    spec_text = out.read_text()  # an attribute-only use expands to plain URDF: no xacro left
    assert "xacro:" not in spec_text and "leak" not in spec_text
    load_spec(out)


def test_a_newline_in_the_file_name_adds_no_yaml(tmp_path: Path) -> None:
    name = "r\nevil_key: 1\n\x1b]0;t\x07\u2028x.urdf"
    src = tmp_path / name
    src.write_text(
        BASE.replace("</robot>", '<transmission name="t"><type>x</type></transmission></robot>')
    )
    out = tmp_path / "r.yaml"
    import_file(src, out)
    text = out.read_text()
    assert "evil_key" not in yaml.safe_load(text)
    assert "\x1b" not in text and "\x07" not in text and "\u2028" not in text
    header = [ln for ln in text.splitlines() if ln.startswith("#")]
    assert any("r\\nevil_key: 1\\n" in ln for ln in header), header
    load_spec(out)
