"""Names from files never start a line of their own or reach the terminal as escapes (issue 27).

GitHub Actions reads `::workflow-command::` lines from stdout and stderr, and a terminal
acts on ESC, OSC and C1 (U+009B) sequences. Before: `armcli tree` of a robot named
`r&#10;::add-mask::X` printed a standalone `::add-mask::X` line; check's plain "end
effector" and "reach of" lines printed link names raw; the import report printed
passthrough attributes and round-trip differences raw; build's "built ... from" line
printed a spec file name with a newline and an OSC title sequence. Names in a URDF are
refused when they hold control characters (one error line naming file and line), and
every other text from a file is printed through io.oneline's escaper.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.helpers import FIXTURES, SPECS, run_cli

INJECT = "&#10;::add-mask::X&#155;2J&#8232;y"  # newline, C1 CSI, line separator (XML has no ESC)
RAW = "\n::add-mask::X\x1b]0;title\x07\x9b2J"
BASE = (FIXTURES / "import" / "sensor_base.urdf").read_text()


def _clean(text: str) -> None:
    """No line starts a workflow command; no ESC, BEL or C1 control reaches the stream."""
    for line in text.splitlines():
        assert not line.lstrip().startswith("::"), line
    assert not any(c in text for c in "\x1b\x07\x9b\u2028"), repr(text)


def _assert_clean(proc: object) -> None:
    _clean(proc.stdout)  # type: ignore[attr-defined]
    _clean(proc.stderr)  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    "edit",
    [
        ('<robot name="sensor_base">', f'<robot name="sensor_base{INJECT}">'),
        ('"base_link"', f'"base_link{INJECT}"'),  # the link and every joint naming it
        ('"base_joint"', f'"base_joint{INJECT}"'),
    ],
    ids=["robot", "link", "joint"],
)
@pytest.mark.parametrize("command", ["tree", "check"])
def test_urdf_names_with_control_characters(
    command: str, edit: tuple[str, str], tmp_path: Path
) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(BASE.replace(*edit))
    proc = run_cli([command, path], cwd=tmp_path)
    _assert_clean(proc)
    assert proc.returncode == 2 and "control characters" in proc.stderr, proc.stderr


def test_import_report_escapes_passthrough_and_differences(tmp_path: Path) -> None:
    inject = "&#10;::add-mask::X&#10;"  # (a C1 character is not YAML: that import is refused)
    extra = f'<transmission name="t"><type>x{inject}</type><note a="{inject}"/></transmission>'
    path = tmp_path / "r.urdf"
    path.write_text(BASE.replace("</robot>", extra + "</robot>"))
    proc = run_cli(["import", path, "-o", tmp_path / "r.yaml"], cwd=tmp_path)
    _assert_clean(proc)
    assert proc.returncode == 0, proc.stderr
    assert "kept verbatim" in proc.stdout


def test_build_line_escapes_the_spec_file_name(tmp_path: Path) -> None:
    name = f"s{RAW}.yaml"
    shutil.copy(SPECS / "tabletop_arm.yaml", tmp_path / name)
    proc = run_cli(["build", name, "-o", "out"], cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    _assert_clean(proc)
    assert "built " in proc.stdout and "\\n::add-mask::X" in proc.stdout
