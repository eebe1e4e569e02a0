"""Every `check` rule fires on a deliberately broken copy of the generated robot, and
only that rule; the clean robot fires none; the course's macro output is caught."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from lxml import etree

from armcli.check.findings import apply_policy
from armcli.check.options import CheckOptions, TipoverOptions
from armcli.check.rules import RULES
from armcli.check.run import check_urdf
from armcli.spec.load import load_spec
from armcli.spec.model import RobotSpec
from armcli.urdf.read import parse_urdf, read_urdf
from armcli.xacro.sandbox import expand_untrusted
from tests.helpers import FIXTURES as ALL_FIXTURES
from tests.helpers import ROOT

FIXTURES = ROOT / "tests" / "fixtures" / "check"
BASE = (ROOT / "urdf" / "my_robot.urdf").read_bytes()
SPEC = load_spec(ROOT / "specs" / "my_robot.yaml")
# The issue: the hand tip is at (0.15, 0, 0.92) m in base_footprint at q = 0
# (base_joint 0.1 + mount 0.2 + arm base 0.02 + forearm 0.3 + hand 0.3; mount x 0.15).
HAND_TIP_HOME = (0.15, 0.0, 0.92)
FK_ATOL = 1e-12


def _el(root: Any, tag: str, name: str) -> Any:
    el = root.find(f"{tag}[@name='{name}']")
    assert el is not None, name
    return el


def link(name: str) -> Callable[[Any], Any]:
    return lambda r: _el(r, "link", name)


def joint(name: str) -> Callable[[Any], Any]:
    return lambda r: _el(r, "joint", name)


HAND, FOREARM, J2, J1 = (
    link("hand_link"),
    link("forearm_link"),
    joint("forearm_hand_joint"),
    joint("arm_base_forearm_joint"),
)


def set_attr(get: Callable[[Any], Any], path: str, attr: str, value: str) -> Callable[[Any], None]:
    def edit(r: Any) -> None:
        el = get(r) if not path else get(r).find(path)
        el.set(attr, value)

    return edit


def remove(get: Callable[[Any], Any], path: str) -> Callable[[Any], None]:
    def edit(r: Any) -> None:
        parent = get(r)
        parent.remove(parent.find(path))

    return edit


def append(xml: str, get: Callable[[Any], Any] | None = None) -> Callable[[Any], None]:
    def edit(r: Any) -> None:
        (get(r) if get else r).append(etree.fromstring(xml))

    return edit


def scale_hand(mass: float) -> Callable[[Any], None]:
    """Give the hand another mass with its inertia scaled to match (shape unchanged)."""

    def edit(r: Any) -> None:
        ine = HAND(r).find("inertial")
        old = float(ine.find("mass").get("value"))
        ine.find("mass").set("value", repr(mass))
        el = ine.find("inertia")
        for a in ("ixx", "iyy", "izz"):
            el.set(a, repr(float(el.get(a)) * mass / old))

    return edit


def scale_hand_inertia(factor: float) -> Callable[[Any], None]:
    """Multiply the hand's inertia (not its mass) by factor."""

    def edit(r: Any) -> None:
        el = HAND(r).find("inertial/inertia")
        for a in ("ixx", "iyy", "izz"):
            el.set(a, repr(float(el.get(a)) * factor))

    return edit


def swap_hand_ixx_izz(r: Any) -> None:
    el = HAND(r).find("inertial/inertia")
    ixx, izz = el.get("ixx"), el.get("izz")
    el.set("ixx", izz)
    el.set("izz", ixx)


def hand_mesh(r: Any) -> None:
    geo = HAND(r).find("visual/geometry")
    geo.remove(geo.find("cylinder"))
    geo.append(etree.fromstring('<mesh filename="package://no_such_pkg/meshes/hand.stl"/>'))


def with_gains(kp: float, kd: float) -> RobotSpec:
    gains = {j: g.model_copy(update={"kp": kp, "kd": kd}) for j, g in SPEC.control.gains.items()}
    return SPEC.model_copy(update={"control": SPEC.control.model_copy(update={"gains": gains})})


def disconnected(r: Any) -> None:
    """Two links that are each other's parent: a cycle away from the root."""
    for xml in (
        '<link name="c1"/>',
        '<link name="c2"/>',
        '<joint name="c12" type="fixed"><parent link="c1"/><child link="c2"/></joint>',
        '<joint name="c21" type="fixed"><parent link="c2"/><child link="c1"/></joint>',
    ):
        r.append(etree.fromstring(xml))


def capsule(r: Any) -> None:
    """An unknown shape in the visual; urdfdom also says it cannot parse the visual."""
    geo = HAND(r).find("visual/geometry")
    geo.remove(geo.find("cylinder"))
    geo.append(etree.fromstring('<capsule radius="0.02" length="0.3"/>'))


def hand_orange_redefined(r: Any) -> None:
    """The hand's visual redefines the top-level orange with another colour."""
    mat = HAND(r).find("visual/material")
    mat.append(etree.fromstring('<color rgba="1 0.6 0 1"/>'))


def tool_without_inertial(r: Any) -> None:
    """A tool with geometry but no <inertial>, fixed to the hand (whose mass carries it)."""
    geo = '<geometry><box size="0.02 0.02 0.02"/></geometry>'
    r.append(
        etree.fromstring(
            f'<link name="tool"><visual>{geo}</visual><collision>{geo}</collision></link>'
        )
    )
    r.append(
        etree.fromstring(
            '<joint name="tool_joint" type="fixed"><parent link="hand_link"/>'
            '<child link="tool"/><origin xyz="0 0 0.3"/></joint>'
        )
    )


SAFE_SPEC = with_gains(50.0, 2.0)  # Kd = 2 keeps even the explicit loop stable at 1 ms
SWING = ALL_FIXTURES / "tipover" / "swing.yaml"


def tipover(spec: RobotSpec | None = None, **kw: Any) -> CheckOptions:
    """Options with balance/reach settings (payload at the tool point, trajectory, ...)."""
    return CheckOptions(spec=spec, tipover=TipoverOptions(**kw))


# (edit of urdf/my_robot.urdf, spec or None, the exact set of rules expected)
def gz_position_servo(gain: float) -> Callable[[Any], None]:
    """A gz_ros2_control block commanding forearm_hand_joint by position at `gain`."""
    block = append(
        '<ros2_control name="s" type="system"><hardware>'
        "<plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>"
        '<joint name="forearm_hand_joint"><command_interface name="position"/>'
        '<state_interface name="position"/></joint></ros2_control>'
    )
    plugin = append(
        '<gazebo><plugin filename="gz_ros2_control-system" '
        'name="gz_ros2_control::GazeboSimROS2ControlPlugin">'
        f"<position_proportional_gain>{gain}</position_proportional_gain></plugin></gazebo>"
    )

    def edit(r: Any) -> None:
        block(r)
        plugin(r)

    return edit


def both(*edits: Callable[[Any], None]) -> Callable[[Any], None]:
    def edit(r: Any) -> None:
        for e in edits:
            e(r)

    return edit


_RAYS = ("<ray><scan><horizontal><samples>36</samples><min_angle>-3.1</min_angle>"
         "<max_angle>3.1</max_angle></horizontal></scan><range><min>{min}</min><max>8</max>"
         "</range></ray>")  # fmt: skip


def _sensor(link: str, kind: str, body: str) -> str:
    return f'<gazebo reference="{link}"><sensor name="s" type="{kind}">{body}</sensor></gazebo>'


CASES: dict[str, tuple[Callable[[Any], None], RobotSpec | CheckOptions | None, set[str]]] = {
    "duplicate-name": (append('<link name="hand_link"/>'), None, {"duplicate-name"}),
    "unknown-link": (set_attr(J2, "parent", "link", "no_such_link"), None, {"unknown-link"}),
    "multiple-parents": (
        append(
            '<joint name="extra" type="fixed"><parent link="arm_base_link"/>'
            '<child link="hand_link"/></joint>'
        ),
        None,
        {"multiple-parents"},
    ),
    "root-count": (append('<link name="floating_frame"/>'), None, {"root-count"}),
    "disconnected": (disconnected, None, {"disconnected"}),
    "joint-type": (set_attr(J2, "", "type", "hinge"), None, {"joint-type"}),
    "missing-limit": (remove(J2, "limit"), None, {"missing-limit"}),
    "mimic-target": (append('<mimic joint="no_such_joint"/>', J2), None, {"mimic-target"}),
    "robot-name": (lambda r: r.attrib.pop("name"), None, {"robot-name"}),
    "material-undefined": (
        set_attr(HAND, "visual/material", "name", "FlatBlack"),
        None,
        {"material-undefined"},
    ),
    "material-conflict": (hand_orange_redefined, None, {"material-conflict"}),
    "number-syntax": (set_attr(HAND, "visual/origin", "xyz", "0 0 0.15m"), None, {"number-syntax"}),
    # One finding per problem: urdfdom's own complaints about the NaN are not repeated.
    "non-finite": (set_attr(HAND, "visual/origin", "xyz", "0 0 nan"), None, {"non-finite"}),
    "vector-length": (set_attr(J2, "origin", "xyz", "0 0"), None, {"vector-length"}),
    "geometry-size": (
        set_attr(HAND, "visual/geometry/cylinder", "radius", "0"),
        None,
        {"geometry-size"},
    ),
    # urdfdom also says it cannot parse that visual.
    "geometry-kind": (capsule, None, {"geometry-kind", "parser-error"}),
    # urdfdom also rejects the colour and then the material.
    "rgba-range": (
        set_attr(lambda r: _el(r, "material", "orange"), "color", "rgba", "2 0.5 0 1"),
        None,
        {"rgba-range", "parser-error"},
    ),
    "mass-nonpositive": (
        set_attr(HAND, "inertial/mass", "value", "-0.3"),
        None,
        {"mass-nonpositive"},
    ),
    "inertia-not-pd": (
        set_attr(HAND, "inertial/inertia", "ixx", "-0.00228"),
        None,
        {"inertia-not-pd"},
    ),
    "inertia-triangle": (
        set_attr(HAND, "inertial/inertia", "izz", "0.01"),
        None,
        {"inertia-triangle"},
    ),
    "tiny-mass": (scale_hand(1e-5), None, {"tiny-mass"}),
    "missing-inertial": (tool_without_inertial, None, {"missing-inertial"}),
    "root-inertia": (
        append(
            '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
            'izz="1"/></inertial>',
            link("base_footprint"),
        ),
        None,
        {"root-inertia"},
    ),
    # 1.5x the solid cylinder: a hollow hand could have it (the bound is 2x on the axis).
    "inertia-geometry": (scale_hand_inertia(1.5), None, {"inertia-geometry"}),
    "inertia-exceeds-geometry": (scale_hand_inertia(4.0), None, {"inertia-exceeds-geometry"}),
    # The same 4x on a hand drawn only by its visual (no collision): weaker evidence, a warning
    "inertia-exceeds-visual": (
        both(scale_hand_inertia(4.0), remove(HAND, "collision")),
        None,
        {"inertia-exceeds-visual", "visual-no-collision"},
    ),
    "com-geometry": (set_attr(HAND, "inertial/origin", "xyz", "0 0 0.2"), None, {"com-geometry"}),
    "limit-order": (set_attr(J2, "limit", "upper", "0"), None, {"limit-order"}),
    "limit-effort-velocity": (
        set_attr(J2, "limit", "velocity", "0"),
        None,
        {"limit-effort-velocity"},
    ),
    "axis": (set_attr(J2, "axis", "xyz", "0 0 0"), None, {"axis"}),
    "axis-unit": (set_attr(J2, "axis", "xyz", "0 2 0"), None, {"axis-unit"}),
    "limit-degrees": (set_attr(J2, "limit", "upper", "90"), None, {"limit-degrees"}),
    "spec-limits": (set_attr(J2, "limit", "upper", "1.5"), SAFE_SPEC, {"spec-limits"}),
    "parser-message": (lambda r: None, None, set()),
    "parser-error": (
        append('<material name="texture_only"><texture/></material>'),
        None,
        {"parser-error"},
    ),
    "model-load": (append('<calibration rising="abc"/>', J2), None, {"model-load"}),
    "gravity-effort": (set_attr(J1, "limit", "effort", "1"), None, {"gravity-effort"}),
    # An implicit-damping divergence is always an explicit one too (Kp bound is looser).
    "pd-unstable": (lambda r: None, with_gains(1e6, 5.0), {"pd-unstable", "pd-explicit-unstable"}),
    "pd-explicit-unstable": (lambda r: None, with_gains(50.0, 5.0), {"pd-explicit-unstable"}),
    # gz_ros2_control position servo: the error is multiplied by (1 - gain) per period
    "servo-unstable": (gz_position_servo(2.5), None, {"servo-unstable"}),
    "servo-oscillates": (gz_position_servo(1.5), None, {"servo-oscillates"}),
    "visual-no-collision": (remove(HAND, "collision"), None, {"visual-no-collision"}),
    "self-collision": (
        set_attr(joint("mobile_base_arm_joint"), "origin", "xyz", "0.15 0 0.15"),
        SAFE_SPEC,
        {"self-collision"},
    ),
    "mesh-missing": (hand_mesh, None, {"mesh-missing"}),
    # The arm held out front-right, 20 mm threshold: 4.38 kg at the hand holds (test_balance)
    "support-margin": (lambda r: None, tipover(payload=6.0), {"support-margin"}),
    "com-outside-support": (lambda r: None, tipover(payload=10.0), {"com-outside-support"}),
    # The arm is 0.6 m long: a point 1 m out is out of reach from everywhere
    "reach-point": (lambda r: None, tipover(reach_points=((1.0, 0.0, 0.5),)), {"reach-point"}),
    # The fast swing alone keeps > 20 mm; braking/accelerating the base on top of it does not
    "zmp-margin": (
        lambda r: None,
        tipover(SAFE_SPEC, trajectory=SWING, base_accel=3.5),
        {"zmp-margin"},
    ),
    # At 5 m/s² the point leaves the polygon for 0.19 s, too briefly to tip the robot (a
    # lift-off: zmp-margin); at 8 m/s² it stays out long enough to rotate it over its wheels
    "zmp-outside-support": (
        lambda r: None,
        tipover(SAFE_SPEC, trajectory=SWING, base_accel=8.0),
        {"zmp-outside-support"},
    ),
    # sensors (more cases: tests/check/test_sensors.py)
    "sensor-link": (append(_sensor("nowhere", "imu", "<update_rate>10</update_rate>")), None,
                    {"sensor-link"}),
    "sensor-rate": (append(_sensor("base_link", "imu", "<update_rate>5000</update_rate>")),
                    None, {"sensor-rate"}),
    "sensor-fov": (append(_sensor("base_link", "camera",
                                  "<camera><horizontal_fov>0</horizontal_fov></camera>")),
                   None, {"sensor-fov"}),
    "sensor-range": (append(_sensor("base_link", "ray", _RAYS.format(min=9))), None,
                     {"sensor-range"}),
    # a lidar in the middle of the base's box, its rays starting 5 cm out: still inside
    "sensor-sees-robot": (append(_sensor("base_link", "ray", _RAYS.format(min=0.05))), None,
                          {"sensor-sees-robot"}),
}  # fmt: skip


def run(edit: Callable[[Any], None], spec: RobotSpec | CheckOptions | None) -> Any:
    root = etree.fromstring(BASE)
    edit(root)
    data = etree.tostring(root, xml_declaration=True, encoding="utf-8")
    opts = spec if isinstance(spec, CheckOptions) else CheckOptions(spec=spec)
    return check_urdf(parse_urdf(data, "broken.urdf"), opts)


def test_every_rule_has_a_case() -> None:
    # parser-message (non-error urdfdom output) has no known trigger with urdfdom 4:
    # everything it prints starts with "Error"; it stays for other parser versions.
    # input-unusable is about files that do not parse at all: test_check_inputs.py; the
    # ROS package rules read directories of packages: tests/check/ros_packages/.
    ros = {r for r in RULES if r.startswith("ros-")}
    assert set(RULES) - set(CASES) == {"input-unusable", *ros}


@pytest.mark.parametrize("rule", sorted(r for r in CASES if r != "parser-message"))
def test_broken_fixture_triggers_exactly_its_rule(rule: str) -> None:
    edit, spec, expected = CASES[rule]
    result = run(edit, spec)
    assert {f.rule for f in result.findings} == expected, [f.message for f in result.findings]
    for f in result.findings:
        assert f.severity == RULES[f.rule].severity and f.hint and f.message


@pytest.mark.parametrize("name", ["my_robot.urdf", "standalone_arm.urdf"])
def test_generated_robot_is_clean(root: Path, built_dir: Path, name: str) -> None:
    for path in (root / "urdf" / name, built_dir / name):
        result = check_urdf(read_urdf(path), CheckOptions(spec=SAFE_SPEC))
        # The standalone arm's massive arm_base_link hangs from a massless `world` root.
        assert {f.rule for f in result.findings} == set(), [f.message for f in result.findings]


def test_summary_of_the_default_robot(root: Path) -> None:
    s = check_urdf(read_urdf(root / "urdf" / "my_robot.urdf"), CheckOptions(spec=SPEC)).summary
    # Spec masses: base 5 + wheels 2 x 1 + caster 0.5 + arm 0.5 + 0.3 + 0.3.
    assert s.total_mass == pytest.approx(8.6, abs=1e-12)
    assert s.dof == 4  # two wheels + two arm joints
    home = next(p for p in s.poses if p.name == "home")
    assert home.xyz == pytest.approx(HAND_TIP_HOME, abs=FK_ATOL)
    # folded: q1 = 1.5 rad from upright, q2 = pi/2 further: planar links of 0.3 m from the
    # shoulder at (0.15, 0, 0.32), angles measured from +z toward +x.
    folded = next(p for p in s.poses if p.name == "folded")
    a, b = 1.5, math.pi / 2
    x = 0.15 + 0.3 * (math.sin(a) + math.sin(a + b))
    z = 0.32 + 0.3 * (math.cos(a) + math.cos(a + b))
    assert folded.xyz == pytest.approx((x, 0.0, z), abs=FK_ATOL)
    j1 = next(j for j in s.joints if j.name == "arm_base_forearm_joint")
    # Worst gravity torque on joint 1: both links horizontal, 0.3 kg at 0.15 m and 0.45 m.
    assert j1.gravity_max == pytest.approx(0.3 * 9.81 * (0.15 + 0.45), rel=1e-9)
    # the example's gains are stable in both loops (the course's Kd 5 is not: below)
    assert s.stability is not None and s.stability.explicit.stable and s.stability.implicit.stable


def test_issue_stability_verdict_for_the_seed_gains(root: Path) -> None:
    course = with_gains(50.0, 5.0)  # the course's Kp 50, Kd 5
    result = check_urdf(read_urdf(root / "urdf" / "standalone_arm.urdf"), CheckOptions(spec=course))
    (f,) = [f for f in result.findings if f.rule == "pd-explicit-unstable"]
    assert f.values["lambda_max"] == pytest.approx(554.0, rel=1e-3)  # the issue's number
    assert "pd-unstable" not in {x.rule for x in result.findings}  # implicit damping is fine


# The course macros: box_inertia(m, l, w, h) gives ixx = m/12 (h² + l²), iyy = m/12 (w² + l²),
# izz = m/12 (w² + h²); the base calls pass 2*size. Solid-body references: box
# m/12 (y²+z², x²+z², x²+y²), cylinder m/12 (3r²+h²) twice and m r²/2, sphere 2/5 m r².
def _course_box(m: float, ln: float, w: float, h: float) -> tuple[float, float, float]:
    return (m / 12 * (h * h + ln * ln), m / 12 * (w * w + ln * ln), m / 12 * (w * w + h * h))


COURSE_FLAGGED = {
    "base_link": (_course_box(5.0, 1.2, 0.8, 0.4), (5 / 12 * 0.2, 5 / 12 * 0.4, 5 / 12 * 0.52)),
    "right_wheel_link": (
        (1 / 12 * (3 * 0.04 + 0.01),) * 2 + (0.5 * 0.04,),
        (1 / 12 * (3 * 0.01 + 0.0025),) * 2 + (0.5 * 0.01,),
    ),
    "left_wheel_link": (
        (1 / 12 * (3 * 0.04 + 0.01),) * 2 + (0.5 * 0.04,),
        (1 / 12 * (3 * 0.01 + 0.0025),) * 2 + (0.5 * 0.01,),
    ),
    "caster_wheel_link": ((0.4 * 0.5 * 0.01,) * 3, (0.4 * 0.5 * 0.0025,) * 3),
    "arm_base_link": (
        _course_box(0.5, 0.1, 0.1, 0.02),
        (0.5 / 12 * 0.0104, 0.5 / 12 * 0.0104, 0.5 / 12 * 0.02),
    ),
}
INERTIA_RTOL = 1e-9
FIX_RTOL = 5e-4  # 4 significant digits


def test_course_macros_are_flagged_link_by_link() -> None:
    data = expand_untrusted(FIXTURES / "course_macros.urdf.xacro")
    result = check_urdf(parse_urdf(data, "course.urdf"))
    found = {
        f.values["link"]: f
        for f in result.findings
        if f.rule in ("inertia-geometry", "inertia-exceeds-geometry")
    }
    assert set(found) == set(COURSE_FLAGGED)  # forearm and hand (correct sizes) pass
    # 4x the solid value is above the all-mass-on-the-extremes bound (3x for a box, 2x for
    # a cylinder's axis and 2.5x for a sphere); the permuted-only arm base is not.
    assert {n for n, f in found.items() if f.rule == "inertia-exceeds-geometry"} == {
        "base_link",
        "right_wheel_link",
        "left_wheel_link",
        "caster_wheel_link",
    }
    for name, (course, solid) in COURSE_FLAGGED.items():
        f = found[name]
        # Inertial and geometry share their origins, so the moments about the shape centre
        # are the macro's diagonal (wheels: both rotated by rpy = (pi/2, 0, 0)).
        key_actual, key_solid = (
            ("about_centre", "solid")
            if f.rule == "inertia-exceeds-geometry"
            else ("actual", "expected")
        )
        assert f.values[key_actual] == pytest.approx(course, rel=INERTIA_RTOL), name
        assert f.values[key_solid] == pytest.approx(solid, rel=INERTIA_RTOL), name
        # The remedy is the solid formula, to the 4 significant digits it is written with.
        fixed = (f.fix["ixx"], f.fix["iyy"], f.fix["izz"])
        assert fixed == pytest.approx(solid, rel=FIX_RTOL), name
    assert "axes permuted" in found["arm_base_link"].message
    assert "axes permuted, 4x too large" in found["base_link"].message
    assert "4x too large" in found["right_wheel_link"].message
    assert {f.rule for f in result.findings} == {"inertia-geometry", "inertia-exceeds-geometry"}


def test_ignore_and_strict() -> None:
    result = run(*CASES["com-geometry"][:2])
    assert apply_policy(result.findings, ignore=["com-geometry"]) == []
    (strict,) = apply_policy(result.findings, strict=True)
    assert strict.severity == "error"


def test_sampled_range_reaches_the_gravity_worst_case() -> None:
    # Joint 1 at pi/2 with joint 2 at 0 is a corner of the range box; with four joints
    # (wheels included) the sample is corners + random draws, and must contain it.
    result = check_urdf(parse_urdf(BASE, "x.urdf"))
    j1 = next(j for j in result.summary.joints if j.name == "arm_base_forearm_joint")
    assert j1.gravity_max == pytest.approx(0.3 * 9.81 * 0.6, rel=1e-9)
    assert math.isfinite(j1.gravity_max)


@pytest.mark.parametrize(
    ("drop", "role"),
    [("collision", "visual"), ("visual", "collision"), (None, "visual and collision")],
)
def test_inertia_exceeds_geometry_names_the_shape_it_measured(drop: str | None, role: str) -> None:
    """A link drawn only by its visual gets "visual shape", not "collision shape"."""

    def edit(r: Any) -> None:
        scale_hand_inertia(4.0)(r)
        if drop:
            HAND(r).remove(HAND(r).find(drop))

    rule = "inertia-exceeds-visual" if drop == "collision" else "inertia-exceeds-geometry"
    (f,) = [f for f in run(edit, None).findings if f.rule == rule]
    assert f"inside that {role} shape can have" in f.message
    # A visual-only shape may be only a picture (Go1's rotors): a warning, not an error.
    assert f.severity == ("warning" if drop == "collision" else "error")
