"""Shared fixtures: repository paths and one session-wide build of the default spec."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_SPEC = ROOT / "specs" / "my_robot.yaml"


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def default_spec_path() -> Path:
    return DEFAULT_SPEC


@pytest.fixture(scope="session")
def built_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The default spec built once per session into a temporary directory."""
    from armcli.build import build

    out = tmp_path_factory.mktemp("built")
    build(DEFAULT_SPEC, out)
    return out
