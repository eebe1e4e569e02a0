"""Shared fixtures: repository paths and one session-wide build of the default spec."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.helpers import DEFAULT_SPEC, ROOT


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def default_spec_path() -> Path:
    return DEFAULT_SPEC


@pytest.fixture(scope="session")
def built_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The default spec built once per session into a temporary directory."""
    from armcli.compiler.expand import build

    out = tmp_path_factory.mktemp("built")
    build(DEFAULT_SPEC, out)
    return out


@pytest.fixture(scope="session")
def armcli_wheel(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The wheel of this checkout, built once per test session, and its wheelhouse.

    The build compiles the engine (minutes): every test that needs the wheel shares it.
    """
    from tests.install_helpers import build_wheel, wheelhouse

    house = wheelhouse()
    return build_wheel(tmp_path_factory.mktemp("wheel"), house), house


def _hypothesis_profiles() -> None:
    """`default` keeps `make test` quick; `make fuzz` selects the long `fuzz` profile."""
    import os

    from hypothesis import HealthCheck, settings

    settings.register_profile(
        "default",
        max_examples=60,
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.too_slow],
    )
    settings.register_profile(
        "fuzz", max_examples=3000, deadline=None, suppress_health_check=list(HealthCheck)
    )
    settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))


_hypothesis_profiles()
