"""Static balance against closed forms, a dense grid, and urdf-validator on the course robot.

The box-on-feet case (tests/fixtures/tipover/box_rod.urdf): a 5 kg base (4 kg box, four
0.25 kg feet) standing on its feet at (+-0.2, +-0.15), a 1 kg point mass l = 0.5 m up a
rod swinging about y at height 0.15 m. With the rod at angle q the centre of mass is
x = sin(q) / 12, z = (0.6 + 0.5 cos q) / 6 (6 kg in all), so the margin toward the front
edge is 0.2 - sin(q) / 12 and the slope that tips it forward has
tan(theta) = (1.2 - 0.5 sin q) / (0.6 + 0.5 cos q), least at the interior angle
q* = atan2(0.3, 0.6) + asin(0.25 / sqrt(0.45)) (zero derivative), not at a corner.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis.balance import analyse
from armcli.analysis.stance import NoStance, Payload, Stance, stance_of
from armcli.check.options import CheckOptions, TipoverOptions
from armcli.check.run import check_urdf
from armcli.compiler.expand import expand_urdfs
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf, read_urdf
from tests.helpers import DEFAULT_SPEC, FIXTURES

BOX_ROD = FIXTURES / "tipover" / "box_rod.urdf"
FEET = ("foot_fl", "foot_fr", "foot_rl", "foot_rr")
EXACT = 1e-12  # [m] closed forms evaluated in double precision
SEARCH = 1e-7  # [m or rad] the search's optimum against the analytic one
UV_MM = 1.0  # [mm] the agreement with urdf-validator
UV_DEG = 0.5  # [deg]


def box_stance(payload: float = 0.0) -> Stance:
    s = stance_of(read_urdf(BOX_ROD), declared=FEET, payload=Payload(payload, "tip"))
    assert isinstance(s, Stance)
    return s


def test_box_polygon_and_named_pose_are_exact() -> None:
    b = analyse(box_stance(), [("zero", {"swing": 0.0}), ("out", {"swing": 0.7})], 0.02)
    assert sorted(b.directions) == ["front", "left", "rear", "right"]
    front = b.directions.index("front")
    for pose, q in zip(b.poses, (0.0, 0.7), strict=True):
        x, z = math.sin(q) / 12, (0.6 + 0.5 * math.cos(q)) / 6
        assert pose.com[0] == pytest.approx(x, abs=EXACT)
        assert pose.com[2] == pytest.approx(z, abs=EXACT)
        assert pose.margins[front] == pytest.approx(0.2 - x, abs=EXACT)
        assert pose.margin == pytest.approx(min(0.15, 0.2 - x), abs=EXACT)  # sides: 0.15
        assert pose.tip_angles[front] == pytest.approx(math.atan2(0.2 - x, z), abs=EXACT)


def test_box_worst_over_the_range_is_found_inside_it() -> None:
    b = analyse(box_stance(), [("zero", {"swing": 0.0})], 0.02)
    front = b.directions.index("front")
    # margin: least with the rod horizontal (a corner of the range)
    assert b.worst[front].margins[front] == pytest.approx(0.2 - 1 / 12, abs=SEARCH)
    # tipping angle: least at the interior q* (see the module docstring)
    q_star = math.atan2(0.3, 0.6) + math.asin(0.25 / math.sqrt(0.45))
    theta = math.atan((1.2 - 0.5 * math.sin(q_star)) / (0.6 + 0.5 * math.cos(q_star)))
    assert b.worst_tip_angles[front] == pytest.approx(theta, abs=SEARCH)
    grid = np.linspace(-math.pi / 2, math.pi / 2, 200001)  # the dense-grid reference
    ref = np.arctan((1.2 - 0.5 * np.sin(grid)) / (0.6 + 0.5 * np.cos(grid))).min()
    assert b.worst_tip_angles[front] == pytest.approx(ref, abs=1e-9)
    corners = [math.atan((1.2 - 0.5 * math.sin(q)) / (0.6 + 0.5 * math.cos(q)))
               for q in (-math.pi / 2, math.pi / 2)]  # fmt: skip
    assert b.worst_tip_angles[front] < min(corners) - 0.01  # corners alone would miss it


def test_box_largest_payload_is_the_closed_form_and_holds_exactly() -> None:
    # rod horizontal: unloaded COM x = 1/12 (6 kg), the mass at x = 0.5; front margin
    # (6 (0.2 - 1/12) + m (0.2 - 0.5)) / (6 + m) = 0.02  =>  m = 6 (0.2 - 1/12 - 0.02) / 0.32
    m_max = 6 * (0.2 - 1 / 12 - 0.02) / 0.32
    b = analyse(box_stance(), [("zero", {"swing": 0.0})], 0.02)
    assert b.payload_max == pytest.approx(m_max, abs=1e-9)
    loaded = analyse(box_stance(m_max), [("out", {"swing": math.pi / 2})], 0.02)
    assert loaded.poses[0].margin == pytest.approx(0.02, abs=EXACT)


def test_box_overloaded_is_an_error_naming_the_payload_that_holds() -> None:
    opts = CheckOptions(tipover=TipoverOptions(payload=3.0, payload_link="tip", contact_links=FEET))
    res = check_urdf(read_urdf(BOX_ROD), opts)
    found = [f for f in res.findings if f.rule == "com-outside-support"]
    assert len(found) == 1
    f = found[0]
    # rod horizontal with 3 kg at x = 0.5: COM x = (0.5 + 1.5) / 9 = 0.2222, 22.2 mm past x = 0.2
    assert f.values["margin"] == pytest.approx(0.2 - 2 / 9, abs=SEARCH)
    assert f.values["direction"] in ("front", "rear")
    assert f.fix == {"payload": 1.8}  # 1.8125 kg rounded down
    assert "over the joint range" in f.message and "1.81 kg at tip holds" in f.message


def test_arm_alone_is_skipped_and_says_so() -> None:
    spec = load_spec(DEFAULT_SPEC)
    arm = parse_urdf(expand_urdfs(spec)["standalone_arm.urdf"], "standalone_arm.urdf")
    assert isinstance(stance_of(arm), NoStance)
    res = check_urdf(arm, CheckOptions(spec=spec))
    assert res.summary is not None and res.summary.balance is None
    assert any(n.startswith("static balance skipped: fixed base") for n in res.summary.notes)


@pytest.fixture(scope="module")
def course() -> Stance:
    spec = load_spec(DEFAULT_SPEC)
    urdf = parse_urdf(expand_urdfs(spec)["my_robot.urdf"], "my_robot.urdf")
    s = stance_of(urdf, candidates=set(spec.mobile_base.links), payload=Payload(0.0, "hand_link"))
    assert isinstance(s, Stance)
    return s


def test_course_robot_by_hand(course: Stance) -> None:
    # 8.6 kg: base 5 at z 0.2, wheels 2 x 1 at (-0.15, 0.1), caster 0.5 at (0.2, 0.05), arm
    # base 0.5 at (0.15, 0.31), forearm 0.3 at (0.15, 0.47), hand 0.3 at (0.15, 0.77) (q = 0)
    x = (-0.3 + 0.1 + 0.075 + 0.045 + 0.045) / 8.6
    z = (1.0 + 0.2 + 0.025 + 0.155 + 0.141 + 0.231) / 8.6
    b = analyse(course, [("home", {})], 0.02)
    assert b.poses[0].com == pytest.approx((x, 0.0, z), abs=EXACT)
    # side edges from the wheels' contacts (-0.15, +-0.225) to the caster's (0.2, 0)
    side = (0.2 - x) * 0.225 / math.hypot(0.35, 0.225)
    assert b.poses[0].margin == pytest.approx(side, abs=EXACT)
    rear = b.directions.index("rear")
    assert b.poses[0].margins[rear] == pytest.approx(x + 0.15, abs=EXACT)


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # its open()
def test_course_robot_agrees_with_urdf_validator(course: Stance) -> None:
    """urdf-validator 1.6.0 (not a dependency: pip install it to run this) at its poses.

    Its margin is the same quantity (distance from the COM to the hull of the wheels'
    and caster's positions). Its single tipping angle is atan(w / 2 / h) with w the
    narrower side of the polygon's bounding box: the angle of a COM centred in a
    rectangle, not of this triangle, whose nearest edges tip it at ~28 deg, not 40.7:
    we reproduce their number from our COM and polygon, and differ on purpose.
    Its payload moves joint torques only, not the COM (a 2 kg payload leaves its margin
    unchanged), so payloads are not compared.
    """
    pytest.importorskip("urdf_validator_main")
    from urdf_validator_main.checks.stability import run as run_stability
    from urdf_validator_main.checks.statics import run as run_statics
    from urdf_validator_main.parser.urdf_adapter import load_urdf
    from urdf_validator_main.report.models import ValidationReport

    path = DEFAULT_SPEC.parent.parent / "urdf" / "my_robot.urdf"
    parsed = load_urdf(str(path))
    poses = [("home", {}), ("reach", {"arm_base_forearm_joint": math.pi / 4,
                                      "forearm_hand_joint": math.pi / 4}),
             ("upper", {"arm_base_forearm_joint": math.pi / 2,
                        "forearm_hand_joint": math.pi / 2})]  # fmt: skip
    ours = analyse(course, poses, 0.02)
    xs = [v[0] for v in course.polygon.vertices]
    ys = [v[1] for v in course.polygon.vertices]
    width = min(max(xs) - min(xs), max(ys) - min(ys))
    for (_, angles), mine in zip(poses, ours.poses, strict=True):
        report = ValidationReport(urdf_path=str(path), robot_name=parsed.name)
        run_statics(parsed, report, joint_angles=angles)
        run_stability(parsed, report, joint_angles=angles)
        assert mine.margin * 1e3 == pytest.approx(report.stability.margin_mm, abs=UV_MM)
        assert mine.com[2] == pytest.approx(report.statics.com_height_above_ground, abs=1e-3)
        theirs = math.degrees(math.atan2(width / 2, mine.com[2] - course.ground.height))
        assert theirs == pytest.approx(report.stability.tipping_angle_deg, abs=UV_DEG)
        assert math.degrees(min(mine.tip_angles)) < report.stability.tipping_angle_deg - 10


def test_base_without_arm_has_no_payload_point_and_no_workspace() -> None:
    """The course base alone (as ros2_control_demos' diffbot): its deepest link is a wheel.

    The balance stands (the polygon and margins do not need an arm); a payload at a
    wheel and the reach of a wheel mean nothing, so both are left out with notes.
    """
    from lxml import etree

    root = etree.fromstring((DEFAULT_SPEC.parent.parent / "urdf" / "my_robot.urdf").read_bytes())
    arm = {"arm_base_link", "forearm_link", "hand_link"}
    for el in list(root):
        child = el.find("child")
        if el.get("name") in arm or (child is not None and child.get("link") in arm):
            root.remove(el)
    base = parse_urdf(etree.tostring(root), "base_only.urdf")
    res = check_urdf(base, CheckOptions(tipover=TipoverOptions(payload=2.0)))
    s = res.summary
    assert s is not None and s.balance is not None and s.reach is None
    assert s.balance.payload is None and s.balance.payload_point == ""
    # base 5 kg at x 0, wheels 2 x 1 kg at x -0.15, caster 0.5 kg at x 0.2 (tests above)
    x = (-0.3 + 0.1) / 7.5
    assert s.balance.poses[0].com[0] == pytest.approx(x, abs=EXACT)
    notes = " ".join(s.notes)
    assert "payload left out" in notes and "workspace skipped" in notes
    assert not res.findings
