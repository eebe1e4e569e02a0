"""check's sensor rules on URDFs with Gazebo sensor tags (tests/fixtures/check/sensors/).

Each broken fixture raises its rule and no other sensor rule; the sound one none. The
count of rays a lidar starts inside the base's box is checked against a closed form: ray
i starts at o + range_min d_i, inside the box when every coordinate is within its half
size. A spec's sensor finding points at the spec's `sensors.NAME` field.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.urdf.read import read_urdf
from tests.helpers import FIXTURES, run_main

pytest.importorskip("mujoco")

SENSORS = FIXTURES / "check" / "sensors"
CASES = {
    "sensors_ok.urdf": set(),
    "sensor_link.urdf": {"sensor-link"},
    "sensor_rate.urdf": {"sensor-rate"},
    "sensor_fov.urdf": {"sensor-fov"},
    "sensor_range.urdf": {"sensor-range"},
    "sensor_sees_robot.urdf": {"sensor-sees-robot"},
}


def _sensor_rules(path: Path) -> list[tuple[str, dict[str, object]]]:
    result = check_urdf(read_urdf(path), CheckOptions())
    return [(f.rule, dict(f.values)) for f in result.findings if f.rule.startswith("sensor-")]


@pytest.mark.parametrize("name", sorted(CASES))
def test_each_fixture_raises_its_rule_only(name: str) -> None:
    assert {rule for rule, _ in _sensor_rules(SENSORS / name)} == CASES[name]


def test_rays_starting_inside_the_base_are_counted_exactly() -> None:
    ((_, values),) = _sensor_rules(SENSORS / "sensor_sees_robot.urdf")
    # the fixture: base_link 0.05 above the root, its box 0.6 x 0.4 x 0.2 centred 0.1 above
    # it; the laser at (0.1, 0, 0.15) in base_link; 360 rays from -3.14159 to 3.14159 rad,
    # starting 0.12 m out
    a = -3.14159 + np.arange(360) * (2 * 3.14159 / 359)
    start = np.column_stack([0.1 + 0.12 * np.cos(a), 0.12 * np.sin(a), np.full(360, 0.15)])
    inside = np.all(np.abs(start - [0.0, 0.0, 0.1]) <= [0.3, 0.2, 0.1], axis=1)
    assert values["rays"] == int(inside.sum()) > 0


def test_a_lidar_on_a_mast_clear_of_the_base_sees_no_robot() -> None:
    assert _sensor_rules(SENSORS / "sensors_ok.urdf") == []


def test_a_spec_sensor_finding_names_the_spec_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = (FIXTURES.parent.parent / "specs" / "rover.yaml").read_text()
    fast = tmp_path / "fast.yaml"
    fast.write_text(spec.replace("    rate: 100\n", "    rate: 5000\n"))
    code, out, _ = run_main(["check", fast], capsys)
    assert code == 1
    assert f"{fast.name}:" in out and "sensors.base_imu.rate" in out and "sensor-rate" in out


def test_a_drive_refuses_a_sensor_faster_than_physics(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = (FIXTURES.parent.parent / "specs" / "rover.yaml").read_text()
    fast = tmp_path / "fast.yaml"
    fast.write_text(spec.replace("    rate: 100\n", "    rate: 5000\n"))
    cmd = tmp_path / "cmd.yaml"
    cmd.write_text("commands:\n  - {linear: {x: 0.1}, time_from_start: 0.0}\n")
    code, _, err = run_main(["simulate", fast, "--cmd-vel", cmd, "--duration", "0.1"], capsys)
    assert code == 2 and "sensor-rate" in err and "--ignore sensor-rate" in err
