"""A directory with unusable files: every usable file is checked, every unusable one is
reported (table, JSON, exit code), exit 2 only when nothing was usable."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from armcli.check.inputs import run_check
from armcli.check.options import CheckOptions
from armcli.errors import EXIT_FAILED, EXIT_OK, EXIT_UNUSABLE
from tests.cli.test_check import armcli
from tests.helpers import ROOT

GOOD = ROOT / "urdf" / "my_robot.urdf"


def mixed_dir(tmp_path: Path) -> Path:
    """Two valid URDFs, a truncated one and an empty one (the issue's directory)."""
    d = tmp_path / "robots"
    (d / "sub").mkdir(parents=True)
    shutil.copy(GOOD, d / "a.urdf")
    shutil.copy(ROOT / "urdf" / "standalone_arm.urdf", d / "sub" / "c.urdf")
    (d / "b_truncated.urdf").write_text(GOOD.read_text()[:500])
    (d / "empty.urdf").write_text("")
    return d


def test_library_checks_every_usable_file(tmp_path: Path) -> None:
    run = run_check([mixed_dir(tmp_path)], CheckOptions())
    assert [Path(r.file).name for r in run.results] == ["a.urdf", "c.urdf"]
    assert sorted(Path(u.file).name for u in run.unusable) == ["b_truncated.urdf", "empty.urdf"]
    assert all(not u.named for u in run.unusable)
    findings = [u.finding() for u in run.unusable]
    assert {f.rule for f in findings} == {"input-unusable"}
    assert run.exit_code(findings) == EXIT_FAILED  # usable files exist: the worst finding
    assert run.exit_code([]) == EXIT_OK  # e.g. --ignore input-unusable


def test_cli_json_lists_every_file_with_its_error(tmp_path: Path) -> None:
    d = mixed_dir(tmp_path)
    r = armcli("check", d, "--format", "json")
    assert r.returncode == 1, r.stderr
    doc = json.loads(r.stdout)
    files = {Path(f["file"]).name: f for f in doc["files"]}
    assert set(files) == {"a.urdf", "c.urdf", "b_truncated.urdf", "empty.urdf"}
    assert files["a.urdf"]["summary"]["robot"] == "my_robot"
    assert "not well-formed" in files["b_truncated.urdf"]["error"]
    assert files["b_truncated.urdf"]["findings"][0]["line"] is not None  # where the XML breaks
    assert files["empty.urdf"]["findings"][0]["rule"] == "input-unusable"
    assert doc["exit_code"] == 1 and doc["counts"]["error"] == 2
    # Each unusable file also has its one line on stderr.
    assert sum(str(d) in line for line in r.stderr.splitlines()) >= 2


def test_cli_table_shows_unusable_rows(tmp_path: Path) -> None:
    r = armcli("check", mixed_dir(tmp_path))
    assert r.returncode == 1
    assert "input-unusable" in r.stdout and "empty.urdf" in r.stdout
    assert "in 2 file(s), 2 unusable" in r.stdout


def test_nothing_usable_exits_2(tmp_path: Path) -> None:
    d = tmp_path / "bad"
    d.mkdir()
    (d / "empty.urdf").write_text("")
    (d / "html.urdf").write_text("<html/>")
    r = armcli("check", d, "--format", "json")
    assert r.returncode == EXIT_UNUSABLE
    doc = json.loads(r.stdout)
    assert doc["exit_code"] == 2 and len(doc["files"]) == 2
    assert all("error" in f for f in doc["files"])
    assert len(r.stderr.splitlines()) == 2  # one line per unusable file
