"""The planning panel's mobile base: a target anywhere in the room, Plan, Execute, replay.

The session (view.baseplan) plans the course robot to a point on the corridor scene's
table, out of the arm's reach from where the base stands; its drawing is checked against
the plan (the path ends at the parked pose, the parked pose lies in the feasible region,
the arm's last ghost reaches the target); then the viser panel (view.basepanel) on a real
server plans and executes, and the replay moves the whole robot's root to the parked pose.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from armcli.plan.mobile.judge import world_to_base
from armcli.view.basepanel import BasePanel, MobileViewer
from armcli.view.baseplan import BaseSession, load_base_session
from armcli.view.panel import PlanningPanel
from armcli.view.planning import load_session
from armcli.view.scene import load_robot
from tests.helpers import DEFAULT_SPEC, FIXTURES

CORRIDOR = FIXTURES / "plan" / "mobile" / "corridor.yaml"
TARGET = (3.0, 0.0, 0.47)  # on the corridor's table (its file), 3 m from the robot
PARKED_TOL = 0.03  # [m] the replay's root ends this near the parked pose (execute: 2 cm tool)
REGION_TOL = 0.05  # [m] a region point lies this near the parked pose (3-degree candidates)


@pytest.fixture(scope="module")
def session() -> BaseSession:
    src = load_robot(DEFAULT_SPEC)
    assert src.file is not None
    found = load_base_session(src.file, CORRIDOR)
    assert found is not None  # the course robot has its diff drive
    return found


def test_plan_draws_the_path_the_region_and_the_ghosts(session: BaseSession) -> None:
    drawing = session.plan_to(TARGET)
    assert drawing is not None, session.reason
    x, y, _ = drawing.parked
    assert np.allclose(drawing.path[-1, :2], (x, y), atol=1e-9)
    assert np.allclose(drawing.path[0, :2], (0.0, 0.0), atol=1e-9)
    assert np.min(np.hypot(drawing.region[:, 0] - x, drawing.region[:, 1] - y)) < REGION_TOL
    planar = session.mobile.planar
    assert planar is not None
    u, w, lateral = planar.coordinates(world_to_base(np.array([drawing.parked]),
                                                     np.array(TARGET))[0])  # fmt: skip
    tip = planar.plane(drawing.ghosts[-1])  # the arm's last ghost: the reaching configuration
    assert math.hypot(tip[0] - u, tip[1] - w, lateral) < 1e-3


def test_a_robot_without_a_drive_gets_no_base_session() -> None:
    src = load_robot(FIXTURES / "plan" / "two_link.urdf")
    assert src.file is not None
    assert load_base_session(src.file) is None


def test_the_panel_plans_executes_and_replays_the_whole_robot(
    session: BaseSession, tmp_path: Path
) -> None:
    """As `armcli view SPEC --scene ROOM` builds it: the arm's planning panel beside."""
    src = load_robot(DEFAULT_SPEC)
    assert src.file is not None
    viewer = MobileViewer(src.xml, name=src.name, poses=src.poses, tool=src.tool, port=0)
    arm = PlanningPanel(viewer, load_session(src.file, scene=CORRIDOR, save_dir=tmp_path), src.xml,
                        source=src.source)  # fmt: skip
    panel = BasePanel(viewer, session, src.xml, source=src.source)
    try:
        panel.move_target(TARGET)
        assert panel.plan(), panel.status
        assert "parks at" in panel.status
        assert panel.execute(wait=True), panel.status
        assert "executed: tool" in panel.status
        assert session.plan is not None
        x, y, _ = session.plan.placement.verdict.base
        root = viewer.base_position()  # where the replay left the robot
        assert math.hypot(root[0] - x, root[1] - y) < PARKED_TOL
        # the room's walls and table stayed in the world while the robot drove (drawn in
        # the base frame, they travelled with it: the robot never came nearer the table)
        scene = viewer.server.scene
        walls = [scene.get_handle_by_name(f"/room/{k}") for k in range(3)]
        assert all(h is not None and np.allclose(h.position, 0.0) for h in walls)
        assert scene.get_handle_by_name("/base/plan/scene/0") is None
        arm.plan()  # the arm's planning panel plans with the base at the origin: it goes back
        assert np.allclose(viewer.base_position(), 0.0)
    finally:
        arm.close()
        panel.close()
        viewer.close()
