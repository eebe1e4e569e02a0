"""Fuzz the trajectory loader (file and `--message` text): only armcli's errors escape.

test_trajectory.py mutates wave.yaml's structure; here the inputs are text edits
of the course's `ros2 topic pub` payload and of pick.yaml, and structured
mutations that put hostile numbers (huge, tiny, negative, integer-valued) where
times and positions go, with and without --clamp. An accepted trajectory must
give a finite reference, since the simulator trusts it.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from armcli.errors import ArmcliError
from armcli.trajectory.message import Trajectory, load_trajectory, loads_trajectory
from armcli.trajectory.reference import build_reference
from tests.helpers import ROOT, mutated

J1, J2 = "arm_base_forearm_joint", "forearm_hand_joint"
LIMITS = {J1: (0.0, math.pi / 2), J2: (0.0, math.pi / 2)}  # urdf/standalone_arm.urdf limits
LIMIT_SLACK = 1e-9  # [rad] trajectory.LIMIT_TOL, the documented tolerance at the limits
PICK = (ROOT / "specs" / "trajectories" / "pick.yaml").read_text()
PAYLOAD = (
    "{header: {frame_id: arm_base_link}, joint_names: [arm_base_forearm_joint, "
    "forearm_hand_joint], points: [{positions: {0.0, 0.0}}]}"
)  # the course's `ros2 topic pub` payload, with ROS's flow-set quirk
SOURCE = "fuzz.yaml"
# Numbers where times and positions go: edges of float, integers beyond float range,
# subnormal times, values at the limits.
HOSTILE_NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**400), max_value=10**400),
    st.sampled_from([0, -0.0, 5e-324, 1e-7, 1e300, math.pi / 2, math.pi / 2 + 1e-10, 2**63]),
)


def _accepted(text: str, clamp: bool) -> Trajectory | None:
    try:
        return loads_trajectory(text, LIMITS, source=SOURCE, clamp=clamp)
    except ArmcliError as exc:
        lines = exc.lines()
        assert lines and all(ln.startswith(SOURCE) for ln in lines), lines
        return None


def _assert_usable(tr: Trajectory) -> None:
    """What simulate relies on: increasing times, finite in-limit positions, finite reference."""
    assert tr.times[0] >= 0 and np.all(np.diff(tr.times) > 0)
    assert np.all(np.isfinite(tr.positions))
    assert np.all(tr.positions >= -LIMIT_SLACK)
    assert np.all(tr.positions <= math.pi / 2 + LIMIT_SLACK)
    ref = build_reference(tr, (J1, J2), np.zeros(2))
    q, v = ref.sample(np.concatenate([tr.times, np.linspace(0.0, tr.duration + 1.0, 40)]))
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(v)), "non-finite reference"


@given(
    base=st.sampled_from([PICK, PAYLOAD]),
    pos=st.integers(0, 10**6),
    cut=st.integers(0, 12),
    insert=st.text(alphabet=st.characters(codec="utf-8"), max_size=10)
    | st.sampled_from(["&a", "*a", "!!python/name:os.system", "{", "]", "\t", "1e999", "-"]),
    clamp=st.booleans(),
)
def test_fuzz_trajectory_text_edits(
    base: str, pos: int, cut: int, insert: str, clamp: bool
) -> None:
    at = pos % (len(base) + 1)
    tr = _accepted(base[:at] + insert + base[at + cut :], clamp)
    if tr is not None:
        _assert_usable(tr)


@st.composite
def hostile_numbers(draw: st.DrawFn) -> dict:
    """pick.yaml with some times and positions replaced by hostile numbers."""
    doc = yaml.safe_load(PICK)
    for _ in range(draw(st.integers(1, 4))):
        point = draw(st.sampled_from(doc["points"]))
        where = draw(st.sampled_from(["positions", "sec", "nanosec", "seconds"]))
        value = draw(HOSTILE_NUMBERS)
        if where == "positions":
            point["positions"][draw(st.integers(0, 1))] = value
        elif where == "seconds":
            point["time_from_start"] = value
        elif isinstance(point.get("time_from_start"), dict):
            point["time_from_start"][where] = value
    return doc


@given(doc=hostile_numbers() | mutated(yaml.safe_load(PICK)), clamp=st.booleans())
def test_fuzz_trajectory_numbers(doc: dict, clamp: bool) -> None:
    tr = _accepted(yaml.safe_dump(doc, allow_unicode=True), clamp)
    if tr is not None:
        _assert_usable(tr)


@given(st.binary(max_size=200))
def test_fuzz_trajectory_file_bytes(tmp_path_factory: pytest.TempPathFactory, data: bytes) -> None:
    """Arbitrary bytes in a trajectory file: refused with the file's name, never a crash."""
    path = tmp_path_factory.mktemp("traj") / "t.yaml"
    path.write_bytes(data)
    try:
        tr = load_trajectory(path, LIMITS)
    except ArmcliError as exc:
        assert all(ln.startswith(str(path)) for ln in exc.lines()), exc.lines()
        return
    _assert_usable(tr)


@pytest.mark.parametrize(
    "text",
    [
        "{joint_names: [arm_base_forearm_joint], points: [{positions: [1%s]}]}" % ("0" * 400),
        "{joint_names: [arm_base_forearm_joint], "
        "points: [{positions: [1], time_from_start: {sec: 1%s}}]}" % ("0" * 400),
    ],
    ids=["position", "sec"],
)
def test_huge_integer_is_an_input_error(text: str) -> None:
    """Found while writing these tests: float() of such a YAML int raised OverflowError."""
    with pytest.raises(ArmcliError, match="points"):
        loads_trajectory(text, LIMITS)


def test_tiny_first_segment_is_an_input_error() -> None:
    """Found by the fuzz profile: a 5e-324 s segment made the linear reference inf/NaN and
    simulate blamed dt or the inertia; trajectory.py now bounds segment durations."""
    text = (
        "{joint_names: [arm_base_forearm_joint, forearm_hand_joint], points: ["
        "{positions: [0.6, 0.4], time_from_start: 5.0e-324}, "
        "{positions: [0.9, 1.2], time_from_start: {sec: 2, nanosec: 0}}]}"
    )
    with pytest.raises(ArmcliError, match=r"points\[0\]\.time_from_start: .*at least"):
        loads_trajectory(text, LIMITS)
