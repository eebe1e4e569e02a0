"""Shared planning contexts: loading a robot and its collision matrix once per module."""

from __future__ import annotations

import sysconfig
from pathlib import Path

import pytest

from armcli.plan.inputs import Loaded, load_context
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC, FIXTURES, ROOT

PLAN_FIXTURES = FIXTURES / "plan"
BOX_SCENE = PLAN_FIXTURES / "box_in_the_way.yaml"
TWO_LINK = PLAN_FIXTURES / "two_link.urdf"
ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix" / "share" / "example-robot-data"
PANDA = ERD / "robots" / "panda_description"
BENCH_SCENES = ROOT / "bench" / "scenes"  # the planning benchmark's scenes (bench_plan.py)


@pytest.fixture(scope="module")
def course() -> Loaded:
    return load_context(read_robot(DEFAULT_SPEC))


@pytest.fixture(scope="module")
def course_box() -> Loaded:
    return load_context(read_robot(DEFAULT_SPEC), scene=BOX_SCENE)


@pytest.fixture(scope="module")
def two_link() -> Loaded:
    return load_context(read_robot(TWO_LINK))


def panda_in(scene: Path | None) -> Loaded:
    """The Panda's arm (seven joints) with its SRDF, in `scene`."""
    if not PANDA.is_dir():
        pytest.skip("example-robot-data's Panda is not installed")
    from armcli.io.packages import PackageLookup

    return load_context(
        read_robot(PANDA / "urdf" / "panda.urdf"),
        srdf=PANDA / "srdf" / "panda.srdf",
        scene=scene,
        joints=[f"panda_joint{i}" for i in range(1, 8)],
        search=PackageLookup({"example-robot-data": ERD}),
    )


@pytest.fixture(scope="module")
def panda() -> Loaded:
    return panda_in(None)


@pytest.fixture(scope="module")
def panda_bin() -> Loaded:
    return panda_in(BENCH_SCENES / "panda_bin.yaml")
