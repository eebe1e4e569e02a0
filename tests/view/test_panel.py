"""The planning panel in a real browser: its widgets, then Plan and Execute clicked in the page.

Headless Chromium (as tests/view/test_browser.py drives it) opens the viewer of the course
robot; the test clicks the page's own buttons through the DOM, waits for the panel's status
line in the page and for the plan's ghost trail in the screenshots, then checks that
executing replays the simulated motion onto the robot.
"""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from armcli.view.browser import Viewer
from armcli.view.panel import PlanningPanel
from armcli.view.planning import load_session
from armcli.view.scene import load_robot
from tests.helpers import run_cli
from tests.view.test_browser import (  # noqa: F401  (the fixture is used by name)
    MIN_PIXELS,
    PAINT_TIMEOUT_S,
    DevTools,
    browser,
    colour_masks,
    save,
    wait_for,
)
from tests.view.viewer_process import view_then_ctrl_c

PLAN_TIMEOUT_S = 60.0  # first plan: OMPL/TOPP-RA imports and seven ghost robots on 2 cores
EXECUTE_TIMEOUT_S = 90.0  # simulation (~1 s alone) plus the replay of the ~2.5 s motion
WIDTH, HEIGHT = 1280, 1000  # [px] the page's size for this test
SCENE_COLUMNS = (0.25, 0.72)  # fractions of the width between the notification and the panel
MIN_DROP_PX = 30  # the forearm's yellow drops ~90 px from upright to reach at this camera
GOAL_TOL = 0.05  # [rad] the executed motion ends near the goal (tracking error ~0.03 rad)


@pytest.fixture
def panel(default_spec_path: Path, tmp_path: Path) -> Iterator[PlanningPanel]:
    src = load_robot(default_spec_path)
    assert src.file is not None
    session = load_session(src.file, save_dir=tmp_path)
    viewer = Viewer(src.xml, name=src.name, poses=src.poses, tool=src.tool, port=0)
    p = PlanningPanel(viewer, session, src.xml, source=src.source)
    try:
        yield p
    finally:
        p.close()
        viewer.close()


def page_text(dev: DevTools) -> str:
    res = dev.call("Runtime.evaluate", expression="document.body.innerText", returnByValue=True)
    return str(res["result"].get("value", ""))


def click(dev: DevTools, label: str) -> None:
    """Click the page's button labelled `label` as a user would (a DOM click event)."""
    js = (
        "(() => { const b = [...document.querySelectorAll('button')]"
        f".find(e => e.textContent.trim() === {json.dumps(label)});"
        " if (!b) return 'missing'; if (b.disabled) return 'disabled'; b.click(); return 'ok'; })()"
    )
    deadline = time.monotonic() + PAINT_TIMEOUT_S
    while True:  # the panel may still be arriving over the websocket
        got = dev.call("Runtime.evaluate", expression=js, returnByValue=True)["result"]["value"]
        if got == "ok" or time.monotonic() > deadline:
            break
        time.sleep(0.3)
    assert got == "ok", f"button {label!r}: {got}"


def wait_text(dev: DevTools, needle: str, timeout: float) -> str:
    deadline = time.monotonic() + timeout
    while True:
        text = page_text(dev)
        if needle in text or time.monotonic() > deadline:
            return text
        time.sleep(0.3)


def in_scene(mask: np.ndarray) -> np.ndarray:
    """`mask` without the notification (left) and the control panel (right) of the page."""
    out = mask.copy()
    w = out.shape[1]
    out[:, : int(SCENE_COLUMNS[0] * w)] = False
    out[:, int(SCENE_COLUMNS[1] * w) :] = False
    return out


def yellow_rows(img: np.ndarray) -> np.ndarray:
    """Image rows of the forearm's yellow inside the 3-D scene."""
    return np.nonzero(in_scene(colour_masks(img)["yellow"]))[0]


def magenta(img: np.ndarray) -> np.ndarray:
    """The trail's colour (view.panel TRAIL_RGBA and PATH_RGB) as lit and blended."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return in_scene((r > 120) & (b > 100) & (g < 0.75 * np.minimum(r, b)))


def test_plan_and_execute_through_the_page(panel: PlanningPanel, browser: Any) -> None:  # noqa: F811
    viewer: Viewer = panel.viewer
    dev = browser(viewer.url)
    # taller and wider than the shared 1024x768 window, so the whole panel and the goal show
    dev.call("Emulation.setDeviceMetricsOverride", width=WIDTH, height=HEIGHT,
             deviceScaleFactor=1, mobile=False)  # fmt: skip

    def robot_drawn(img: np.ndarray) -> bool:
        m = colour_masks(img)
        return bool(m["blue"].sum() > MIN_PIXELS and m["yellow"].sum() > MIN_PIXELS)

    home = wait_for(dev, robot_drawn, PAINT_TIMEOUT_S)
    assert robot_drawn(home), "the robot was never drawn"
    text = wait_text(dev, "Planning", PAINT_TIMEOUT_S)
    for widget in ("Planning", "Start", "Goal", "Plan", "Execute", "Save"):
        assert widget in text, f"{widget!r} missing from the page"
    save(home, "panel_home.png")
    before = int(magenta(home).sum())  # the drag handle's pink parts are magenta too

    click(dev, "Plan")  # start <current> (home), goal reach: the panel's defaults
    text = wait_text(dev, "planned:", PLAN_TIMEOUT_S)
    assert "planned:" in text, text[-400:]
    assert panel.trail_visible()
    planned = wait_for(dev, lambda im: magenta(im).sum() > before + MIN_PIXELS, PLAN_TIMEOUT_S)
    save(planned, "panel_planned.png")
    assert magenta(planned).sum() > before + MIN_PIXELS, "the ghost trail is not drawn"

    row_home = yellow_rows(home).mean()
    click(dev, "Execute")
    text = wait_text(dev, "executed", EXECUTE_TIMEOUT_S)
    assert "executed;" in text, text[-400:]  # not "executed, broken: ..."
    goal = panel.session.as_dict(panel.session.goal)

    def arrived(img: np.ndarray) -> bool:
        q = viewer.configuration()
        near = all(abs(q[j] - v) < GOAL_TOL for j, v in goal.items())
        ys = yellow_rows(img)
        return near and len(ys) > 0 and ys.mean() - row_home > MIN_DROP_PX  # it leaned over

    deadline = time.monotonic() + EXECUTE_TIMEOUT_S
    while panel.replaying() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not panel.replaying(), "the replay did not finish"
    done = wait_for(dev, arrived, EXECUTE_TIMEOUT_S)
    save(done, "panel_executed.png")
    assert arrived(done), viewer.configuration()

    click(dev, "Save")
    text = wait_text(dev, "wrote ", PAINT_TIMEOUT_S)
    saved = panel.session.save_dir / "plan.yaml"
    assert saved.read_bytes() == panel.session.result.document


def test_cli_refuses_a_missing_save_dir_before_serving(root: Path, tmp_path: Path) -> None:
    proc = run_cli(["view", "--port", "0", "--save-dir", tmp_path / "nowhere"], root)
    assert proc.returncode == 2
    assert proc.stderr == f"error: --save-dir: {tmp_path / 'nowhere'} is not a directory\n"
    assert proc.stdout == ""  # no URL: the server never started


def test_cli_bad_scene_names_file_line_and_field(root: Path, tmp_path: Path) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "collision_objects:\n"
        "  - id: b\n"
        "    primitives: [{type: pyramid, dimensions: [1]}]\n"
        "    primitive_poses: [{}]\n"
    )
    proc = run_cli(["view", "--port", "0", "--scene", scene], root)
    assert proc.returncode == 2
    assert proc.stderr.startswith(
        f"error: {scene}:3 collision_objects[0].primitives[0].type: unknown primitive 'pyramid'"
    )
    assert proc.stdout == ""


def test_cli_robot_without_joints_gets_the_viewer_without_a_panel(
    root: Path, tmp_path: Path
) -> None:
    urdf = tmp_path / "block.urdf"
    urdf.write_text(
        '<robot name="block"><link name="base">'
        '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>'
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
        '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"'
        ' ixy="0" ixz="0" iyz="0"/></inertial></link></robot>'
    )
    first, code, out, err = view_then_ctrl_c([str(urdf), "--port", "0"], root)
    assert first.startswith("armcli view: block at http://127.0.0.1:"), first
    assert code == 0, err
    assert out == "viewer stopped\n"
    # one note (wrapped at the 80 columns readline exports to the child under pytest)
    assert err.startswith("note: no planning panel:") and err.count("note:") == 1, err


def test_cli_unknown_planning_joint_is_refused(root: Path) -> None:
    proc = run_cli(["view", "--port", "0", "--joints", "elbow"], root)
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: --joints: unknown joint 'elbow'; valid: "), proc.stderr
    assert "arm_base_forearm_joint" in proc.stderr and proc.stdout == ""


def test_a_drive_replay_carries_the_panel_and_the_tool_dot_with_the_base(
    default_spec_path: Path, tmp_path: Path
) -> None:
    """The goal ghost, its handle, the trail and the tool dot are drawn in the robot's root
    frame: during a drive's replay they hang from the moving base, as the robot does (they
    stayed where the robot started)."""
    from armcli.sim.states import load_replay
    from armcli.view.png import joint_limits, load_urdf

    cmd = tmp_path / "drive.yaml"
    cmd.write_text(
        "commands:\n  - {linear: {x: 0.3}, time_from_start: 0}\n  - {time_from_start: 1}\n"
    )
    states = tmp_path / "run.csv"
    proc = run_cli(["simulate", default_spec_path, "--cmd-vel", cmd, "-o", states])
    assert proc.returncode == 0, proc.stderr
    src = load_robot(default_spec_path)
    assert src.file is not None
    names = list(joint_limits(load_urdf(src.xml, src.source, src.mesh_dir, src.search)))
    run = load_replay(states, names)  # as `armcli view --replay` reads it
    assert run.base is not None  # a drive's states file: the base moves
    viewer = Viewer(src.xml, name=src.name, tool=src.tool, replay=run, port=0)
    try:
        panel = PlanningPanel(viewer, load_session(src.file, save_dir=tmp_path), src.xml,
                              source=src.source)  # fmt: skip
        names = [viewer._tool_marker.name, panel._handle.name,
                 *(f.name for f in viewer._frames.values())]  # fmt: skip
        assert all(n.startswith("/base/") for n in names), names
        panel.close()
    finally:
        viewer.close()
