"""`armcli --version`: armcli's version, the simulator engine, pin and xacro; no heavy imports."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

import armcli
from armcli.commands.version import version_lines
from armcli.errors import BuildError
from armcli.sim import native
from tests.helpers import ROOT


def test_version_is_pyprojects() -> None:
    # pyproject.toml is the one place the version is written
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert armcli.__version__ == project["version"]


def test_version_lines() -> None:
    lines = version_lines()
    assert lines[0] == f"armcli {armcli.__version__} ({Path(armcli.__file__).parent})"
    assert lines[1].startswith(("simulator engine: compiled (", "simulator engine: Python ("))
    assert lines[2:4] == [f"pin {metadata.version('pin')}", f"xacro {metadata.version('xacro')}"]


def test_engine_without_the_cpp_source(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    # what a wheel without _native/ looks like: the Python loop, said in one line, no crash
    monkeypatch.setattr(native, "SOURCE", tmp_path / "rollout.cpp")
    assert native.load() is None
    assert version_lines()[1] == (
        "simulator engine: Python (no compiled rollout: this installation has no rollout.cpp)"
    )
    with pytest.raises(BuildError, match="is not installed"):
        native.build()


def test_version_option_is_fast() -> None:
    # stays cheap: versions from metadata, no pinocchio/matplotlib/xacro import
    code = (
        "import sys\n"
        "from armcli.cli import main\n"
        "try:\n    main(['--version'])\nexcept SystemExit as e:\n    assert e.code in (0, None)\n"
        "heavy = {'pinocchio', 'matplotlib', 'xacro', 'scipy'} & set(sys.modules)\n"
        "assert not heavy, heavy\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"armcli {armcli.__version__} (")
