"""JointTrajectory input (validation, the ROS payload quirk) and interpolation boundaries."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given
from scipy.interpolate import BPoly, CubicHermiteSpline

from armcli.errors import ArmcliError, SpecError
from armcli.trajectory.message import DEFAULT_SEGMENT_S, load_trajectory, loads_trajectory
from armcli.trajectory.reference import build_reference, segment_coeffs
from tests.helpers import ROOT, mutated

J1, J2 = "arm_base_forearm_joint", "forearm_hand_joint"
LIMITS = {J1: (0.0, math.pi / 2), J2: (0.0, math.pi / 2)}  # the seed's joint limits
SEED = (
    "{header: {frame_id: arm_base_link}, joint_names: [arm_base_forearm_joint, "
    "forearm_hand_joint], points: [{positions: {0.0, 0.0}}]}"
)  # verbatim from the course's `ros2 topic pub` command
EXACT = 1e-12  # closed-form boundary values, only round-off allowed


def _sample1(ref, t: float) -> tuple[np.ndarray, np.ndarray]:
    q, v = ref.sample(np.array([t]))
    return q[0], v[0]


def test_seed_payload_runs_as_written() -> None:
    """The course's `{0.0, 0.0}`: ROS 2 sends one position; armcli runs the two written."""
    tr = loads_trajectory(SEED, LIMITS)
    assert tr.positions.tolist() == [[0.0, 0.0]]
    assert len(tr.warnings) == 1
    assert "points[0].positions" in tr.warnings[0] and "[0.0, 0.0]" in tr.warnings[0]


def _ros2_topic_pub_positions(payload: str) -> list[list[float]]:
    """What `ros2 topic pub` puts in points[k].positions: yaml.safe_load, then
    rosidl_runtime_py.set_message_fields' `array.array('d', value)` on the sequence field."""
    import array

    doc = yaml.safe_load(payload)
    return [list(array.array("d", p["positions"])) for p in doc["points"]]


@pytest.mark.parametrize(
    "positions", ["{0.5, 0.3}", "{0.3, 0.5}", "{0, 1.5}", "{0.0, 0.0}", "{1, 1.0}", "{0.5}"]
)
def test_brace_form_runs_as_written_and_says_what_ros_2_sends(positions: str) -> None:
    payload = f"{{joint_names: [{J1}, {J2}], points: [{{positions: {positions}}}]}}"
    sent = _ros2_topic_pub_positions(payload)[0]  # the independent reference: ROS's own code
    written = [float(x) for x in positions.strip("{}").split(",")]  # what the student typed
    if len(written) != 2:  # nothing to recover: one value for two joints
        with pytest.raises(SpecError, match=r"1 value\(s\) for 2 joint\(s\)"):
            loads_trajectory(payload, LIMITS)
        return
    tr = loads_trajectory(payload, LIMITS)
    assert tr.positions.tolist() == [written]
    assert len(tr.warnings) == 1 and "is a YAML mapping, not a list" in tr.warnings[0]
    list_form = "[" + positions.strip("{}") + "]"
    assert f"write a list: {list_form}" in tr.warnings[0] or list_form in tr.warnings[0]
    if len(sent) != len(written):  # ROS 2 collapses the repeated key: the warning says so
        assert f"would send its distinct keys, {len(sent)} value(s)" in tr.warnings[0]


def test_brace_form_one_warning_for_every_point() -> None:
    points = ", ".join(f"{{positions: {{0.{k}, 0.{k}}}}}" for k in range(1, 6))
    tr = loads_trajectory(f"{{joint_names: [{J1}, {J2}], points: [{points}]}}", LIMITS)
    assert tr.positions[:, 0].tolist() == [0.1, 0.2, 0.3, 0.4, 0.5]  # as written, per point
    assert len(tr.warnings) == 1 and "(and 4 more)" in tr.warnings[0]


EXAMPLES = sorted((ROOT / "specs" / "trajectories").glob("*.yaml"))


@pytest.mark.parametrize("path", [p for p in EXAMPLES if "\ncommands:" not in p.read_text()])
def test_example_trajectories_load(path: Path) -> None:  # drive.yaml: tests/drive/test_cmdvel.py
    tr = load_trajectory(path, LIMITS)
    assert tr.positions.shape[1] == 2
    assert np.all(np.diff(tr.times) > 0)


def test_time_forms_sec_nanosec_and_seconds() -> None:
    text = (
        "joint_names: [arm_base_forearm_joint]\n"
        "points:\n"
        "  - {positions: [0.1], time_from_start: {sec: 1, nanosec: 500000000}}\n"
        "  - {positions: [0.2], time_from_start: 2.25}\n"
        "  - {positions: [0.3]}\n"
    )
    tr = loads_trajectory(text, LIMITS)
    # 1 s + 0.5e9 ns; 2.25 s as given; missing = previous + DEFAULT_SEGMENT_S
    np.testing.assert_allclose(tr.times, [1.5, 2.25, 2.25 + DEFAULT_SEGMENT_S], rtol=0, atol=EXACT)


@pytest.mark.parametrize(
    ("text", "field", "needle"),
    [
        ("joint_names: [elbow]\npoints: [{positions: [0]}]", "joint_names[0]", J1),
        (
            f"joint_names: [{J1}, {J2}]\npoints: [{{positions: [0.1]}}]",
            "points[0].positions",
            "has 1",
        ),
        (
            f"joint_names: [{J1}]\npoints:\n - {{positions: [0.1], time_from_start: 2}}\n"
            " - {positions: [0.2], time_from_start: 1}",
            "points[1].time_from_start",
            "increase",
        ),
        (
            f"joint_names: [{J1}]\npoints: [{{positions: [.nan]}}]",
            "points[0].positions[0]",
            "finite",
        ),
        (
            f"joint_names: [{J1}]\npoints: [{{positions: [2.0]}}]",
            "points[0].positions[0]",
            "limits",
        ),
        (
            f"joint_names: [{J1}]\npoints: [{{positions: [0.1], speed: 1}}]",
            "points[0].speed",
            "unknown",
        ),
        (f"joint_names: [{J1}]\npoints: []", "points", "non-empty"),
    ],
)
def test_invalid_trajectories_name_file_field_and_line(text: str, field: str, needle: str) -> None:
    with pytest.raises(SpecError) as exc:
        loads_trajectory(text, LIMITS, source="traj.yaml")
    line = exc.value.lines()[0]
    assert line.startswith("traj.yaml:")
    assert field in line and needle in line


def test_clamp_turns_limit_error_into_warning() -> None:
    text = f"joint_names: [{J1}]\npoints: [{{positions: [2.0]}}]"
    tr = loads_trajectory(text, LIMITS, clamp=True)
    assert tr.positions[0, 0] == pytest.approx(math.pi / 2)
    assert len(tr.warnings) == 1 and "clamped" in tr.warnings[0]


def test_linear_segments_hit_points_and_hold_after_end() -> None:
    text = (
        f"joint_names: [{J1}, {J2}]\npoints:\n - {{positions: [0.4, 0.2], time_from_start: 1}}\n"
        " - {positions: [0.8, 1.0], time_from_start: 3}"
    )
    tr = loads_trajectory(text, LIMITS)
    q0 = np.array([0.1, 0.0])
    ref = build_reference(tr, (J1, J2), q0)
    q, v = _sample1(ref, 0.0)
    np.testing.assert_allclose(q, q0, atol=EXACT)  # starts from the current state
    q, v = _sample1(ref, 1.0)
    np.testing.assert_allclose(q, [0.4, 0.2], atol=EXACT)
    q, v = _sample1(ref, 2.0)  # midpoint of the second segment: mean of the two points
    np.testing.assert_allclose(q, [0.6, 0.6], atol=EXACT)
    np.testing.assert_allclose(v, [0.2, 0.4], atol=EXACT)  # slope (0.8-0.4)/2, (1.0-0.2)/2
    q, v = _sample1(ref, 10.0)
    np.testing.assert_allclose(q, [0.8, 1.0], atol=EXACT)
    np.testing.assert_array_equal(v, [0.0, 0.0])


def test_first_point_at_time_zero_is_the_reference_from_the_start() -> None:
    tr = loads_trajectory(
        f"joint_names: [{J1}]\npoints: [{{positions: [0.5], time_from_start: 0}}]", LIMITS
    )
    ref = build_reference(tr, (J1, J2), np.zeros(2))
    q, _ = _sample1(ref, 0.0)
    np.testing.assert_allclose(q, [0.5, 0.0], atol=EXACT)  # J2 not named: holds its start


def test_cubic_segment_matches_scipy_hermite() -> None:
    h, p0, p1, v0, v1 = 1.7, np.array([0.2]), np.array([1.1]), np.array([0.5]), np.array([-0.3])
    c = segment_coeffs(h, p0, p1, v0, v1)
    ts = np.linspace(0, h, 41)
    mine = sum(c[k, 0] * ts**k for k in range(6))
    spline = CubicHermiteSpline([0, h], [p0[0], p1[0]], [v0[0], v1[0]])  # independent reference
    np.testing.assert_allclose(mine, spline(ts), atol=1e-12)


def test_quintic_segment_matches_scipy_bpoly_boundaries() -> None:
    h = 1.3
    p0, v0, a0 = 0.1, 0.4, -1.0
    p1, v1, a1 = 0.9, -0.2, 2.0
    c = segment_coeffs(h, *(np.array([x]) for x in (p0, p1, v0, v1, a0, a1)))[:, 0]
    poly = np.polynomial.Polynomial(c)
    ref = BPoly.from_derivatives([0, h], [[p0, v0, a0], [p1, v1, a1]])  # independent
    ts = np.linspace(0, h, 31)
    np.testing.assert_allclose(poly(ts), ref(ts), atol=1e-11)
    for order, (at0, ath) in enumerate(((p0, p1), (v0, v1), (a0, a1))):
        d = poly.deriv(order) if order else poly
        assert d(0.0) == pytest.approx(at0, abs=1e-10)
        assert d(h) == pytest.approx(ath, abs=1e-10)


def test_cubic_reference_velocities_at_knots() -> None:
    tr = load_trajectory(ROOT / "specs" / "trajectories" / "wave.yaml", LIMITS)
    assert tr.velocities is not None
    ref = build_reference(tr, (J1, J2), np.zeros(2))
    q, v = ref.sample(tr.times)
    np.testing.assert_allclose(q, tr.positions, atol=1e-12)
    np.testing.assert_allclose(v, tr.velocities, atol=1e-12)


WAVE = yaml.safe_load((ROOT / "specs" / "trajectories" / "wave.yaml").read_text())


@given(mutated(WAVE))
def test_fuzz_trajectory_structured(doc: object) -> None:
    try:
        text = yaml.safe_dump(doc, allow_unicode=True)
    except yaml.YAMLError:
        return
    try:
        tr = loads_trajectory(text, LIMITS, source="fuzz.yaml")
    except ArmcliError as exc:
        assert all(ln.startswith("fuzz.yaml") for ln in exc.lines()), exc.lines()
        return
    # accepted: times increase, positions finite and within limits, reference finite
    assert np.all(np.diff(tr.times) > 0) and tr.times[0] >= 0
    assert np.all(np.isfinite(tr.positions))
    assert np.all(tr.positions >= -1e-9) and np.all(tr.positions <= math.pi / 2 + 1e-9)
    ref = build_reference(tr, (J1, J2), np.zeros(2))
    q, v = ref.sample(np.linspace(0, tr.duration + 1, 50))
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(v))


def _problems(text: str, **kw: object) -> list[str]:
    with pytest.raises(SpecError) as exc:
        loads_trajectory(text, LIMITS, **kw)  # type: ignore[arg-type]
    return exc.value.lines()


def test_a_typo_is_one_message_with_a_suggestion() -> None:
    points = "".join(f"  - {{postions: [0.{k}, 0.{k}]}}\n" for k in range(1, 6))
    lines = _problems(f"joint_names: [{J1}, {J2}]\npoints:\n{points}")
    assert len(lines) == 1  # not one per point, and not also "positions: missing"
    assert "points[0].postions" in lines[0] and "did you mean 'positions'?" in lines[0]
    assert "(and 4 more)" in lines[0]


def test_joint_names_suggest_and_say_what_a_wheel_is() -> None:
    (line,) = _problems(
        f"joint_names: [arm_base_forarm_joint, {J2}]\npoints: [{{positions: [0, 0]}}]"
    )
    assert f"did you mean {J1!r}?" in line
    wheel = {"base_left_wheel_joint": "a wheel joint of the mobile base"}
    text = f"joint_names: [base_left_wheel_joint, {J2}]\npoints: [{{positions: [0, 0]}}]"
    (line,) = _problems(text, others=wheel)
    assert "'base_left_wheel_joint' is a wheel joint of the mobile base, not an arm joint" in line


def test_degrees_are_named_as_degrees() -> None:
    head = f"joint_names: [{J1}, {J2}]\npoints:\n"
    # one message for the file, not one per value
    (line,) = _problems(head + "  - {positions: [45, 60]}\n  - {positions: [30, 60]}")
    # 45° = 45 pi / 180 = 0.785398... rad
    assert "looks like degrees: 45° = 0.785 rad" in line and "--clamp" not in line
    # out of range in radians too: the limit, once per joint
    (line,) = _problems(head + "  - {positions: [2, 0.1]}\n  - {positions: [2, 0.2]}")
    assert "(use --clamp to clamp)" in line and "(and 1 more)" in line
