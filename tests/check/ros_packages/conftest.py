"""Generated ROS packages (ros-package's own output), once per session, to edit per test."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.check.ros_packages.workspaces import generate


@pytest.fixture(scope="session")
def jazzy_pkgs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The course spec's jazzy packages, generated once (copy before editing)."""
    return generate(tmp_path_factory.mktemp("jazzy"), "jazzy")


@pytest.fixture(scope="session")
def classic_pkgs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The course spec's humble-classic packages, generated once (copy before editing)."""
    return generate(tmp_path_factory.mktemp("classic"), "humble-classic")
