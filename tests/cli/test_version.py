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
from armcli.sim import native
from tests.helpers import ROOT


def test_version_is_pyprojects() -> None:
    # pyproject.toml is the one place the version is written
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert armcli.__version__ == project["version"]


def test_version_lines() -> None:
    lines = version_lines()
    assert lines[0] == f"armcli {armcli.__version__} ({Path(armcli.__file__).parent})"
    assert lines[1].startswith(("simulator engine: compiled (", "simulator engine: unavailable ("))
    assert lines[2:4] == [f"pin {metadata.version('pin')}", f"xacro {metadata.version('xacro')}"]
    assert lines[4].startswith(("camera rendering: EGL (", "camera rendering: OSMesa (",
                                "camera rendering: none ("))  # fmt: skip


def test_engine_when_the_compiled_simulator_is_missing(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(native, "load", lambda: None)
    monkeypatch.setattr(native, "why_missing", lambda: "not built")
    assert version_lines()[1] == "simulator engine: unavailable (not built)"


def test_version_option_is_fast() -> None:
    # stays cheap: versions from metadata, not from importing the libraries (pinocchio may
    # load where the compiled engine links it: asking for the engine is asking for it)
    code = (
        "import sys\n"
        "from armcli.cli import main\n"
        "try:\n    main(['--version'])\nexcept SystemExit as e:\n    assert e.code in (0, None)\n"
        "heavy = {'matplotlib', 'xacro', 'scipy', 'viser', 'yourdfpy'} & set(sys.modules)\n"
        "assert not heavy, heavy\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"armcli {armcli.__version__} (")
