"""The planning panel's logic without a browser: goals, live IK, plan, trail, execute, save.

Expected positions come from the course robot's closed-form kinematics (the brief: the
arm pivots at (0.15, 0, 0.32) in base_footprint, forearm and hand 0.3 m each, both joints
tilting towards +x about y), never from the code under test.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError, OutputRefusedError, PlanningError
from armcli.urdf.source import RobotInput
from armcli.view.browser import Viewer
from armcli.view.panel import DRAGGED, PlanningPanel
from armcli.view.planning import PlanningSession, load_session
from armcli.view.scene import load_robot
from armcli.xacro.args import XacroInputs

PIVOT = np.array([0.15, 0.0, 0.32])  # [m] arm_base_forearm_joint in base_footprint (brief)
LINK = 0.3  # [m] forearm and hand lengths (brief)
FK_TOL = 1e-6  # [m] Pinocchio vs the closed form
IK_TOL = 1.5e-4  # [m] plan.ik's POSITION_TOL (1e-4 m) with rounding room
END_TOL = 1e-9  # [rad] the plan's first and last points are its start and goal
TRACK_TOL = 0.05  # [rad] the simulated arm ends this close to the goal (PD, gravity)
MESH_TOL = 1e-9  # [m] a box's corners vs its pose and half-extents
ROTATION_TOL = 1.5e-3  # [rad] plan.ik's ROTATION_TOL (1e-3 rad) with rounding room


def tip(q: np.ndarray) -> np.ndarray:
    """Closed-form tool point of the course arm at (q1, q2) [rad]."""
    q1, q2 = float(q[0]), float(q[1])
    return PIVOT + LINK * np.array(
        [math.sin(q1) + math.sin(q1 + q2), 0.0, math.cos(q1) + math.cos(q1 + q2)]
    )


@pytest.fixture(scope="module")
def robot(default_spec_path: Path):
    return load_robot(default_spec_path)


@pytest.fixture
def session(robot, tmp_path: Path) -> PlanningSession:
    return load_session(robot.file, save_dir=tmp_path)


@pytest.fixture
def boxed(robot, tmp_path: Path) -> PlanningSession:
    """The course robot with a 0.1 m box around the tool point of its `reach` pose."""
    x, _, z = (float(v) for v in tip(np.array([math.pi / 4, math.pi / 4])))
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "collision_objects:\n"
        "  - id: box\n"
        "    primitives: [{type: box, dimensions: [0.1, 0.1, 0.1]}]\n"
        f"    primitive_poses: [{{position: {{x: {x!r}, y: 0.0, z: {z!r}}}}}]\n"
    )
    return load_session(robot.file, scene=scene, save_dir=tmp_path)


def test_poses_and_tool_match_the_closed_form(session: PlanningSession) -> None:
    assert session.joints == ("arm_base_forearm_joint", "forearm_hand_joint")
    assert session.pose_names == ("home", "reach", "folded")  # the spec's order
    assert np.array_equal(session.start, [0.0, 0.0])  # home
    for name in session.pose_names:
        x = session.pose(name)
        assert session.tool(x)[0] == pytest.approx(tip(x), abs=FK_TOL)


def test_plan_draws_a_trail_from_start_to_goal(session: PlanningSession) -> None:
    session.set_goal(session.pose("reach"))
    result = session.plan()
    assert result is not None and session.reason is None
    trail = session.trail()
    assert len(trail.poses) == 7
    assert trail.poses[0] == pytest.approx(session.start, abs=END_TOL)
    assert trail.poses[-1] == pytest.approx(session.goal, abs=END_TOL)
    # the tool's path starts upright at (0.15, 0, 0.92) and ends at reach's closed form
    assert trail.tool_path[0] == pytest.approx((0.15, 0.0, 0.92), abs=FK_TOL)
    assert trail.tool_path[-1] == pytest.approx(tip(session.goal), abs=FK_TOL)
    reach = np.linalg.norm(trail.tool_path - PIVOT, axis=1)
    assert np.all(reach <= 2 * LINK + FK_TOL)  # two 0.3 m links never reach farther
    assert np.allclose(trail.tool_path[:, 1], 0.0, atol=FK_TOL)  # planar arm: y stays 0


def test_a_joint_subset_plans_only_those(robot, tmp_path: Path) -> None:
    session = load_session(robot.file, joints=["forearm_hand_joint"], save_dir=tmp_path)
    assert session.joints == ("forearm_hand_joint",)
    session.set_goal([math.pi / 4])
    assert session.plan() is not None
    # the forearm stays upright (rest 0): the tool swings on a 0.3 m circle about the elbow
    elbow = PIVOT + np.array([0.0, 0.0, LINK])
    radius = np.linalg.norm(session.trail().tool_path - elbow, axis=1)
    assert radius == pytest.approx(np.full(len(radius), LINK), abs=FK_TOL)


def test_a_failed_plan_is_one_line_and_no_trail(boxed: PlanningSession) -> None:
    boxed.set_goal(boxed.pose("reach"))  # the hand ends inside the box
    assert boxed.plan() is None
    assert boxed.reason == "goal is in collision: hand_link and box"
    session = boxed
    with pytest.raises(PlanningError, match="nothing planned yet"):
        session.trail()


def test_dragging_the_tool_solves_ik_or_keeps_the_goal(session: PlanningSession) -> None:
    target = tip(np.array([0.3, 0.9]))  # reachable by construction, collision-free
    outcome = session.drag_goal(list(target))
    assert outcome.x is not None and outcome.text() == "goal: tool point reached"
    assert tip(session.goal) == pytest.approx(target, abs=IK_TOL)  # closed form, not Pinocchio
    before = session.goal.copy()
    far = session.drag_goal((1.5, 0.0, 0.5))  # 1.35 m from the pivot: beyond 0.6 m of arm
    assert far.x is None and np.array_equal(session.goal, before)
    assert far.distance >= 1.35 - 2 * LINK - IK_TOL  # no point of the arm's reach is closer
    assert "no collision-free IK solution; closest" in far.text()


def test_execute_simulates_the_plan_and_keeps_its_states(session: PlanningSession) -> None:
    session.set_goal(session.pose("reach"))
    assert session.plan() is not None
    done = session.execute()
    assert not done.broken, done.problems
    states = done.states
    assert states is not None
    assert states.duration >= session.result.duration_s
    end = states.positions_at(float(states.time[-1]))
    ref = states.reference_at(float(states.time[-1]))
    assert ref is not None
    for j, goal in session.as_dict(session.goal).items():
        assert ref[j] == pytest.approx(goal, abs=END_TOL)  # the reference ends at the goal
        assert end[j] == pytest.approx(goal, abs=TRACK_TOL)  # and the simulated arm near it


def test_save_writes_the_document_inside_the_save_dir_only(
    session: PlanningSession, tmp_path: Path
) -> None:
    with pytest.raises(PlanningError, match="nothing planned yet"):
        session.save("plan.yaml")
    session.set_goal(session.pose("reach"))
    result = session.plan()
    assert result is not None
    assert session.save("plan.yaml").read_bytes() == result.document
    outside = tmp_path.parent / "outside.yaml"
    os.symlink(outside, tmp_path / "link.yaml")
    for name, why in [
        ("../outside.yaml", "outside the output directory"),
        (str(outside), "outside the output directory"),
        ("plan.txt", "ends in .yaml or .yml"),
        ("link.yaml", "symbolic link"),
        ("missing/plan.yaml", "does not exist"),
    ]:
        with pytest.raises(OutputRefusedError, match=why):
            session.save(name)
    assert not outside.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.yaml", "plan.yaml"]


def test_scene_obstacles_become_meshes_where_the_scene_puts_them(
    robot,
    tmp_path: Path,
) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "collision_objects:\n"
        "  - id: shelf\n"
        "    header: {frame_id: world}\n"
        "    primitives: [{type: box, dimensions: [0.2, 0.4, 0.1]}]\n"
        "    primitive_poses: [{position: {x: 0.7, y: 0.1, z: 0.3}}]\n"
    )
    session = load_session(robot.file, scene=scene, save_dir=tmp_path)
    (mesh,) = session.obstacles()
    assert mesh.id == "shelf"
    # an axis-aligned box: its corners are the pose +- half the dimensions
    assert mesh.vertices.min(axis=0) == pytest.approx((0.6, -0.1, 0.25), abs=MESH_TOL)
    assert mesh.vertices.max(axis=0) == pytest.approx((0.8, 0.3, 0.35), abs=MESH_TOL)
    assert len(mesh.faces) == 12  # two triangles per face


@pytest.fixture
def panel(robot, boxed: PlanningSession) -> Iterator[PlanningPanel]:
    viewer = Viewer(robot.xml, name=robot.name, poses=robot.poses, tool=robot.tool, port=0)
    p = PlanningPanel(viewer, boxed, robot.xml, source=robot.source)
    try:
        yield p
    finally:
        p.close()
        viewer.close()


def test_panel_widgets_drive_the_session(panel: PlanningPanel) -> None:
    session = panel.session
    assert np.array_equal(session.goal, session.pose("reach"))  # the first pose after home
    panel.viewer.set_configuration(session.as_dict(session.pose("reach")))  # hand in the box
    assert not panel.plan()  # start <current>: the robot's pose
    assert panel.status == "no plan: start is in collision: hand_link and box"
    panel.choose_start("folded")  # a named start also moves the robot there
    folded = session.pose("folded")
    assert panel.viewer.tool_position() == pytest.approx(tip(folded), abs=FK_TOL)
    panel.choose_start("<current>")
    panel.choose_goal("home")
    panel.choose_goal("reach")  # into the box
    assert not panel.plan()
    assert panel.status == "no plan: goal is in collision: hand_link and box"
    assert not panel.trail_visible()
    assert panel.save() is None and panel.status.startswith("not saved: nothing planned")
    panel.drag(tuple(tip(np.array([0.2, 0.6]))))
    assert panel.status == "goal: tool point reached"
    assert panel._goal_box.value == DRAGGED
    assert panel.plan() and panel.trail_visible()  # from the current pose (folded) to the drag
    assert session.start == pytest.approx(folded, abs=END_TOL)
    assert panel.status.startswith("planned: ") and panel.status.endswith("; certified")
    saved = panel.save()
    assert saved is not None and saved.read_bytes() == session.result.document


def test_panda_drag_solves_position_and_orientation(tmp_path: Path) -> None:
    """Seven joints and a finger: the handle's rotation counts; yourdfpy (second engine) agrees."""
    from armcli.io.packages import PackageLookup
    from armcli.view.png import load_urdf
    from tests.plan.conftest import ERD, PANDA

    if not PANDA.is_dir():
        pytest.skip("example-robot-data's Panda is not installed")
    packages = PackageLookup({"example-robot-data": ERD})
    src = load_robot(RobotInput((PANDA / "urdf" / "panda.urdf",), XacroInputs(packages=packages)))
    assert src.file is not None and src.tool is not None
    session = load_session(src.file, srdf=PANDA / "srdf" / "panda.srdf", search=src.search,
                           save_dir=tmp_path)  # fmt: skip
    assert session.pose_names == ("default",)  # the SRDF's one group_state
    session.set_goal(session.pose("default"))
    p, R = session.tool(session.goal)
    target = p + np.array([0.0, 0.1, -0.05])  # 11 cm away, same orientation
    assert session.drag_goal(target, R).x is not None
    urdf = load_urdf(src.xml, src.source, src.mesh_dir, src.search)
    urdf.update_cfg(
        {**{j: 0.0 for j in urdf.actuated_joint_names}, **session.as_dict(session.goal)}
    )
    T = urdf.get_transform(src.tool.link, urdf.base_link)
    assert T[:3, :3] @ np.asarray(src.tool.xyz) + T[:3, 3] == pytest.approx(target, abs=IK_TOL)
    angle = math.acos(np.clip((np.trace(T[:3, :3].T @ R) - 1) / 2, -1.0, 1.0))
    assert angle < ROTATION_TOL
    assert session.plan() is not None, session.reason
    with pytest.raises(InputError, match=r"no PD gains to simulate with: .*armcli import"):
        session.execute()  # a URDF carries no gains


def test_save_names_from_the_page_are_refused_in_one_line(session: PlanningSession) -> None:
    """Issue 42: a NUL byte was a ValueError, 5,000 characters an OSError: never answered."""
    session.set_goal(session.pose("reach"))
    assert session.plan() is not None
    for name, why in [
        ("a\0b.yaml", "control characters or NUL"),
        ("x" * 5000 + ".yaml", "too long"),
        ("line\nbreak.yaml", "control characters"),
    ]:
        with pytest.raises(OutputRefusedError, match=why):
            session.save(name)
    assert sorted(p.name for p in session.save_dir.iterdir()) == []


def test_save_replaces_only_what_the_viewer_wrote_unless_confirmed(
    session: PlanningSession,
) -> None:
    """Issue 42: Save overwrote any file in the save directory (root's `roots-notes.yaml`)."""
    notes = session.save_dir / "roots-notes.yaml"
    notes.write_text("my notes\n")
    session.set_goal(session.pose("reach"))
    result = session.plan()
    assert result is not None
    with pytest.raises(OutputRefusedError, match="exists and this viewer did not write it"):
        session.save("roots-notes.yaml")
    assert notes.read_text() == "my notes\n"
    plan = session.save("plan.yaml")
    assert session.save("plan.yaml") == plan  # its own file: saved again without asking
    plan.write_text("edited elsewhere\n")  # changed since: no longer what the viewer wrote
    with pytest.raises(OutputRefusedError, match="did not write it"):
        session.save("plan.yaml")
    assert plan.read_text() == "edited elsewhere\n"
    assert session.save("plan.yaml", overwrite=True).read_bytes() == result.document
    os.replace(notes, plan)  # another file in its place
    with pytest.raises(OutputRefusedError, match="did not write it"):
        session.save("plan.yaml")
