"""`check` reads the URDF's command interface: effort -> PD bound, gz position -> servo bound.

Reference for the servo bound: gz_ros2_control's write() law, simulated here directly
(velocity = gain * update_rate * (q_cmd - q), held for one control period), which
must converge exactly when the rule says "stable" and without sign changes exactly
when it says "no oscillation".
"""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.check import interface as ci
from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.ros.packages import ros_packages
from armcli.spec.load import load_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf
from tests.helpers import ROOT, course_gains_spec

RATE = 1000.0  # [Hz] the spec's controller_update_rate
PERIODS = 200  # control periods simulated per gain
GAINS = [0.05, 0.1, 0.5, 0.99, 1.0, 1.01, 1.5, 1.99, 2.01, 2.5, -0.1]


@pytest.fixture(scope="module")
def spec() -> RobotSpec:
    return load_spec(ROOT / "specs" / "my_robot.yaml")


@pytest.fixture(scope="module")
def gz_urdf(spec: RobotSpec, tmp_path_factory: pytest.TempPathFactory) -> bytes:
    import xacro

    files = ros_packages(spec, samples=10, target="jazzy").files
    tmp = tmp_path_factory.mktemp("gz")
    for path, data in files.items():
        if path.startswith("my_robot_description/urdf/"):
            (tmp / Path(path).name).write_bytes(data)
    doc = xacro.process_file(
        str(tmp / "standalone_arm_gz.urdf.xacro"), mappings={"controllers_file": "/c.yaml"}
    )
    return bytes(doc.toprettyxml(indent="  ", encoding="utf-8"))


def _position(text: bytes, gain: float | None = None) -> bytes:
    out = text.replace(b'command_interface name="effort"', b'command_interface name="position"')
    if gain is not None:
        tag = f"</parameters><position_proportional_gain>{gain}</position_proportional_gain>"
        out = out.replace(b"</parameters>", tag.encode(), 1)
    return out


def _servo(gain: float) -> tuple[bool, bool]:
    """(converges, never changes sign) of gz_ros2_control's position law, simulated."""
    q, q_cmd, T = 0.0, 1.0, 1.0 / RATE
    errors = []
    for _ in range(PERIODS):
        v = gain * RATE * (q_cmd - q)  # GazeboSimSystem::write(), POSITION branch
        q += v * T
        errors.append(q_cmd - q)
    converges = abs(errors[-1]) < abs(q_cmd)  # below the initial error
    monotone = all(e >= 0 for e in errors)
    return converges, monotone


def test_effort_interface_keeps_the_pd_bound(gz_urdf: bytes, tmp_path: Path) -> None:
    ifaces = ci.read_interfaces(parse_urdf(gz_urdf, "gz.urdf"))
    assert ifaces is not None and ifaces.gazebo and ifaces.position_joints() == []
    course = load_spec(course_gains_spec(tmp_path))  # Kd 5: the explicit loop diverges
    res = check_urdf(parse_urdf(gz_urdf, "gz.urdf"), CheckOptions(spec=course))
    assert res.summary is not None and res.summary.stability is not None
    assert "pd-explicit-unstable" in {f.rule for f in res.findings}


def test_position_interface_reports_the_servo_bound_instead(
    gz_urdf: bytes, spec: RobotSpec
) -> None:
    res = check_urdf(parse_urdf(_position(gz_urdf), "gz.urdf"), CheckOptions(spec=spec))
    assert res.summary is not None and res.summary.stability is None
    rules = {f.rule for f in res.findings}
    assert not rules & {"pd-explicit-unstable", "pd-unstable", "servo-unstable"}
    note = next(n for n in res.summary.notes if "first-order servo" in n)
    # default gain 0.1 at the spec's 1000 Hz: v = 100/s x error, error x 0.9 per period
    assert "0.1 x error" in note and "(100/s)" in note and "factor 0.9 " in note


@pytest.mark.parametrize("gain", GAINS)
def test_servo_verdict_matches_the_simulated_law(
    gz_urdf: bytes, spec: RobotSpec, gain: float
) -> None:
    res = check_urdf(parse_urdf(_position(gz_urdf, gain), "gz.urdf"), CheckOptions(spec=spec))
    rules = {f.rule for f in res.findings}
    converges, monotone = _servo(gain)
    assert ("servo-unstable" in rules) == (not converges)
    assert ("servo-oscillates" in rules) == (converges and not monotone)


def test_mock_hardware_and_no_block_are_left_to_the_pd_bound(gz_urdf: bytes) -> None:
    mock = _position(gz_urdf).replace(ci.GZ_SYSTEMS[0].encode(), b"mock_components/GenericSystem")
    ifaces = ci.read_interfaces(parse_urdf(mock, "mock.urdf"))
    assert ifaces is not None and not ifaces.gazebo
    bare = parse_urdf(b"<robot name='r'><link name='a'/></robot>", "bare.urdf")
    assert ci.read_interfaces(bare) is None
