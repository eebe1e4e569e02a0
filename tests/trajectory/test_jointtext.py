"""Plan's layout read by trajectory.jointtext gives the YAML reader's data, float for float."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from armcli.errors import SpecError
from armcli.io.yaml import loads_yaml
from armcli.plan.output import trajectory_yaml
from armcli.plan.timing import Timed
from armcli.trajectory.jointtext import canonical_doc
from armcli.trajectory.message import Trajectory, loads_trajectory, parse_trajectory

NAMES = ("joint_a", "arm/b-2", "c.3")
finite = st.floats(allow_nan=False, allow_infinity=False)


def document(values: np.ndarray, times: np.ndarray, comment: str = "") -> bytes:
    timed = Timed(times, values, -values, values[:, ::-1].copy())
    return trajectory_yaml(NAMES, timed, frame_id="base_link", comment=comment)


def same(a: object, b: object) -> bool:
    """Equal data, floats compared by bits (so -0.0 is not 0.0)."""
    if isinstance(a, float) and isinstance(b, float):
        return math.copysign(1.0, a) == math.copysign(1.0, b) and a == b
    if isinstance(a, dict) and isinstance(b, dict):
        return list(a) == list(b) and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(finite, finite, finite), min_size=1, max_size=6))
def test_any_floats_read_alike(rows: list[tuple[float, float, float]]) -> None:
    values = np.array(rows, dtype=float)
    text = document(values, np.arange(len(rows)) * 0.01, "armcli plan test").decode()
    fast = canonical_doc(text, "<t>")
    assert fast is not None
    assert same(fast.data, loads_yaml(text, "<t>", flow_sets=True).data)


def test_edge_numbers_read_alike() -> None:
    # repr's forms: exponents with and without a dot, subnormals, huge, negative zero
    edge = [0.0, -0.0, 1e-05, -1e-05, 5e-324, 1.7976931348623157e308, 1e16, 123456789.125]
    values = np.array([edge[i : i + 3] for i in range(0, 6)], dtype=float)
    text = document(values, np.array([0.0, 1e-9, 0.5, 1.0, 2.0, 1e4])).decode()
    fast = canonical_doc(text, "<t>")
    assert fast is not None
    assert same(fast.data, loads_yaml(text, "<t>", flow_sets=True).data)


def test_other_layouts_go_to_the_yaml_reader() -> None:
    text = document(np.zeros((2, 3)), np.array([0.0, 1.0])).decode()
    for changed in (
        text.replace("joint_a", "joint a"),  # a name outside the simple set
        text.replace("0.0, 0.0, 0.0]", "0, 0.0, 0.0]", 1),  # an int, not repr's float
        text.replace("points:", "points: # the motion"),
        text.replace("    velocities", "    velocitys"),
        text + "extra: 1\n",
        text.rstrip("\n"),
    ):
        assert canonical_doc(changed, "<t>") is None


def test_a_problem_is_reported_with_its_line() -> None:
    # plan's layout, but a position beyond the limit: the YAML reader's message, with a line
    text = document(np.full((2, 3), 5.0), np.array([0.0, 1.0])).decode()
    limits = {n: (-1.0, 1.0) for n in NAMES}
    with pytest.raises(SpecError) as info:
        loads_trajectory(text, limits, source="<t>")
    assert info.value.problems[0].line == 4  # `  - positions: [5.0, ...]`, the first point


def outcome(read: Callable[..., Trajectory], *args: Any, **kwargs: Any) -> tuple[object, ...]:
    """What a reader gives: the trajectory's fields (floats by bits) or the problems."""
    try:
        t = read(*args, **kwargs)
    except SpecError as exc:
        return ("error", exc.problems)
    arrays = (t.times, t.positions, t.velocities, t.accelerations)
    return (t.joint_names, t.frame_id, t.warnings, *(np.asarray(a).tobytes() for a in arrays))


@pytest.mark.parametrize("clamp", [False, True])
def test_the_array_checks_give_the_yaml_readers_trajectory(clamp: bool) -> None:
    # trajectory.message checks plan's layout on arrays; the reference is parse_trajectory on
    # the YAML reader's data: every check it makes, passing or not, must come out the same
    rng = np.random.default_rng(5)
    limits = {n: (-1.0, 1.0) for n in NAMES}
    times = np.cumsum(rng.uniform(0.01, 0.5, 6))
    short = np.insert(times[1:], 1, times[1] + 5e-7)  # 500 ns after the second point
    cases = {
        "fine": (rng.uniform(-1, 1, (6, 3)), times),
        "at the limits": (np.clip(rng.uniform(-2, 2, (6, 3)), -1 - 1e-9, 1 + 1e-9), times),
        "beyond a limit": (rng.uniform(-1.5, 1.5, (6, 3)), times),
        "times repeat": (rng.uniform(-1, 1, (6, 3)), np.repeat(times[:3], 2)),
        "too short a segment": (rng.uniform(-1, 1, (6, 3)), short),
        "first point just after 0": (rng.uniform(-1, 1, (6, 3)), times - times[0] + 5e-7),
        "first point at 0": (rng.uniform(-1, 1, (6, 3)), times - times[0]),
        "too late": (rng.uniform(-1, 1, (6, 3)), times + 2e6),
    }
    for name, (values, t) in cases.items():
        text = document(values, t).decode()
        for others in ({}, {"c.3": "a wheel joint"}):
            fast = outcome(loads_trajectory, text, limits, clamp=clamp, others=others)
            doc = loads_yaml(text, "<message>", flow_sets=True)
            ref = outcome(parse_trajectory, doc, limits, clamp=clamp, others=others)
            assert fast == ref, name
            passes = name in ("fine", "at the limits", "first point at 0") or (
                clamp and name == "beyond a limit"
            )
            assert (fast[0] != "error") == (passes and not others), name
