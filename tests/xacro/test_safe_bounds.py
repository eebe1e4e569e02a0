"""Safe-mode xacro, issue 20: what an include may reveal or smuggle in.

A glob include (`/root/.*rc`) was matched anywhere and the refusal named the match
(`/root/.bashrc`), telling the file's author which files exist outside the allowed
directories; an included UTF-16 file with a DOCTYPE and entities was expanded, since
the refusal searched the bytes for `<!DOCTYPE`.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.errors import InputError, XacroRefusedError
from armcli.urdf.source import read_urdf_file

NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
DOCTYPE = '<!DOCTYPE r [<!ENTITY e "smuggled">]>'


def _top(tmp_path: Path, include: str) -> Path:
    path = tmp_path / "pkg" / "robot.xacro"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        f'<?xml version="1.0"?>\n<robot name="r" {NS}>\n'
        f'  <xacro:include filename="{include}"/>\n  <link name="base"/>\n</robot>\n'
    )
    return path


def test_glob_outside_the_roots_names_no_match(tmp_path: Path) -> None:
    secret_dir = tmp_path / "home"
    secret_dir.mkdir()
    (secret_dir / ".secretrc").write_text("<robot/>")
    path = _top(tmp_path, f"{secret_dir}/.*rc")
    with pytest.raises(XacroRefusedError, match="outside the allowed directories") as info:
        read_urdf_file(path)
    assert ".secretrc" not in str(info.value)  # before: "included file '.../.secretrc' is ..."


def test_glob_matches_through_links_out_of_the_roots_are_dropped(tmp_path: Path) -> None:
    outside = tmp_path / "outside.xacro"
    outside.write_text(f'<robot {NS}><link name="from_outside"/></robot>')
    path = _top(tmp_path, "parts/*.xacro")
    parts = path.parent / "parts"
    parts.mkdir()
    (parts / "a.xacro").write_text(f'<robot {NS}><link name="from_inside"/></robot>')
    (parts / "b.xacro").symlink_to(outside)
    text = read_urdf_file(path).text
    assert b"from_inside" in text and b"from_outside" not in text


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le"], ids=["bom", "no-bom"])
def test_utf16_include_with_a_doctype_is_refused(encoding: str, tmp_path: Path) -> None:
    path = _top(tmp_path, "part.xacro")
    declaration = '<?xml version="1.0" encoding="UTF-16"?>\n' if encoding == "utf-16" else ""
    (path.parent / "part.xacro").write_bytes(
        f'{declaration}{DOCTYPE}\n<robot {NS}><link name="&e;"/></robot>\n'.encode(encoding)
    )
    with pytest.raises(InputError, match=r"part\.xacro' (is not UTF-8 text|holds NUL)"):
        read_urdf_file(path)  # before: a link named "smuggled"


def test_utf8_include_still_expands(tmp_path: Path) -> None:
    path = _top(tmp_path, "part.xacro")
    (path.parent / "part.xacro").write_text(f'<robot {NS}><link name="ünïcode"/></robot>\n')
    assert "ünïcode".encode() in read_urdf_file(path).text
