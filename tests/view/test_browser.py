"""`armcli view`: the viewer's Python API, replay files, the port rule, Ctrl-C, and a real browser.

The browser test starts headless Chromium (software WebGL through SwiftShader),
drives it over the DevTools protocol, and checks the screenshots for the
robot's colours and for the forearm moving when a joint is set through the API.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import math
import os
import shutil
import socket
import subprocess
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from armcli.errors import InputError
from armcli.sim.states import load_replay
from armcli.view.browser import Viewer, moving_parts
from armcli.view.scene import load_robot
from tests.helpers import run_cli
from tests.view.viewer_process import view_then_ctrl_c

TIP_TOL = 1e-6  # [m] forward kinematics vs closed form
INTERP_TOL = 1e-12  # [rad] linear interpolation of a linear record is exact
PAINT_TIMEOUT_S = 90.0  # SwiftShader's first frame on a loaded 2-core machine
MOVE_TIMEOUT_S = 30.0
MIN_PIXELS = 300  # robot parts cover at least this many pixels at 1024x768
MIN_DROP_PX = 15  # the forearm's centroid drops at least this much when folded
ARM = ("arm_base_forearm_joint", "forearm_hand_joint")
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-quic",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--window-size=1024,768",
    "--remote-debugging-port=0",
)


@pytest.fixture(scope="module")
def robot(default_spec_path: Path):
    return load_robot(default_spec_path)


@pytest.fixture
def viewer(robot) -> Iterator[Viewer]:
    v = Viewer(robot.xml, name=robot.name, poses=robot.poses, tool=robot.tool, port=0)
    try:
        yield v
    finally:
        v.close()


def test_api_moves_joints_and_reports_the_tool(viewer: Viewer) -> None:
    assert viewer.url.startswith("http://127.0.0.1:")
    # The brief: hand tip at (0.15, 0, 0.92) in base_footprint at q = 0.
    assert viewer.tool_position() == pytest.approx((0.15, 0.0, 0.92), abs=TIP_TOL)
    viewer.apply_pose("folded")  # a = 1.5 rad from upright, then the hand a further pi/2
    a, b = 1.5, math.pi / 2
    # planar two-link chain from the shoulder at (0.15, 0, 0.32), links 0.3 m, angles from +z
    elbow = (0.15 + 0.3 * math.sin(a), 0.32 + 0.3 * math.cos(a))
    tip = (elbow[0] + 0.3 * math.sin(a + b), elbow[1] + 0.3 * math.cos(a + b))
    assert viewer.tool_position() == pytest.approx((tip[0], 0.0, tip[1]), abs=TIP_TOL)
    viewer.set_configuration({"forearm_hand_joint": 0.0})  # the other joint keeps 1.5
    assert viewer.configuration()["arm_base_forearm_joint"] == pytest.approx(a)
    straight = (0.15 + 0.6 * math.sin(a), 0.0, 0.32 + 0.6 * math.cos(a))
    assert viewer.tool_position() == pytest.approx(straight, abs=TIP_TOL)
    with pytest.raises(InputError, match="unknown movable joint 'elbow'; known: "):
        viewer.set_configuration({"elbow": 0.1})
    with pytest.raises(InputError, match="outside its limits"):
        viewer.set_configuration({"forearm_hand_joint": -0.5})
    with pytest.raises(InputError, match="unknown pose 'wave'; known: home, reach, folded"):
        viewer.apply_pose("wave")
    viewer.show_frames(True)
    viewer.close()
    viewer.close()  # idempotent


def test_taken_port_is_a_clear_error(robot) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        with pytest.raises(InputError, match=f"cannot listen on 127.0.0.1:{port}: .*in use"):
            Viewer(robot.xml, port=port)


def write_run(path: Path, *, rows: int = 21, blank_refs_after: int | None = None) -> None:
    """A simulate-style CSV: q1 = 0.5 t, q2 = 0.25 t over 2 s; references a step ahead."""
    head = ["time"]
    for j in ARM:
        head += [f"{j}.position", f"{j}.velocity", f"{j}.effort", f"{j}.reference"]
    lines = [",".join(head)]
    for k in range(rows):
        t = 0.1 * k
        cells = [f"{t:.3f}"]
        for rate in (0.5, 0.25):
            ref = "" if blank_refs_after is not None and k >= blank_refs_after else f"{rate * 1.5}"
            cells += [f"{rate * t:.6f}", f"{rate}", "0", ref]
        lines.append(",".join(cells))
    path.write_text("\n".join(lines) + "\n")


def test_replay_file_is_read_and_interpolated(tmp_path: Path) -> None:
    csv = tmp_path / "states.csv"
    write_run(csv, blank_refs_after=10)
    run = load_replay(csv, ["base_left_wheel_joint", *ARM])
    assert run.duration == pytest.approx(2.0)
    at = run.positions_at(0.73)  # between samples: q is linear in t, so interpolation is exact
    assert at == pytest.approx({ARM[0]: 0.5 * 0.73, ARM[1]: 0.25 * 0.73}, abs=INTERP_TOL)
    assert run.reference_at(0.55) == pytest.approx({ARM[0]: 0.75, ARM[1]: 0.375})
    assert run.reference_at(1.5) is None  # blank reference cells: no ghost there


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda t: t.replace("forearm_hand_joint.position", "elbow.position"),
            r"states.csv:1: unknown joint 'elbow'; known: .*forearm_hand_joint",
        ),
        (lambda t: t.replace("0.300,", "0.100,", 1), r"states.csv:5 time: time must increase"),
        (
            lambda t: t.replace("0.100000", "abc", 1),
            r"states.csv:4 arm_base_forearm_joint.position: expected a finite number, got 'abc'",
        ),
        (lambda t: t.replace("time,", "t,", 1), r"states.csv:1: first column must be 'time'"),
    ],
)
def test_bad_replay_file_names_line_and_column(tmp_path: Path, edit: Any, message: str) -> None:
    csv = tmp_path / "states.csv"
    write_run(csv)
    csv.write_text(edit(csv.read_text()))
    with pytest.raises(InputError, match=message):
        load_replay(csv, list(ARM))


def test_replay_seek_play_and_ghost(robot, tmp_path: Path) -> None:
    csv = tmp_path / "states.csv"
    write_run(csv, blank_refs_after=10)
    run = load_replay(csv, list(ARM))
    with Viewer(robot.xml, tool=robot.tool, replay=run, port=0) as v:
        v.seek(0.6)
        assert v.configuration()[ARM[0]] == pytest.approx(0.5 * 0.6)
        assert v.ghost_visible()
        v.seek(1.6)
        assert not v.ghost_visible()  # the file has no reference after t = 1.0 s
        v.seek(0.0)
        v.play()
        time.sleep(0.6)
        v.play(False)
        moved = v.configuration()[ARM[0]]
        assert 0.0 < moved <= 0.5 * 2.0


def test_ghost_shows_only_the_links_the_references_move(robot) -> None:
    from armcli.urdf.read import parse_urdf

    ghost = parse_urdf(moving_parts(robot.xml, ARM).encode(), "ghost")
    # The seed's arm joints move forearm_link and, below it, hand_link; nothing else.
    assert {lk.name for lk in ghost.links if lk.visuals} == {"forearm_link", "hand_link"}
    assert len(ghost.links) == len(parse_urdf(robot.xml.encode(), "full").links)


def test_cli_view_port_taken_exits_2(root: Path) -> None:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        proc = run_cli(["view", "--port", str(port)], root)
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: --port: cannot listen on 127.0.0.1:{port}: ")
    assert proc.stdout == ""


def test_cli_view_stops_cleanly_on_ctrl_c(root: Path) -> None:
    first, code, out, err = view_then_ctrl_c(["--port", "0"], root)
    assert first.startswith("armcli view: my_robot at http://127.0.0.1:"), first
    assert code == 0, err
    assert out == "viewer stopped\n"
    assert err == ""


# -- real browser --------------------------------------------------------------------


class DevTools:
    """A minimal Chrome DevTools Protocol client over one page's websocket."""

    def __init__(self, ws_url: str) -> None:
        from websockets.sync.client import connect

        self._ws = connect(ws_url, max_size=None, open_timeout=20)
        self._id = 0

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        self._id += 1
        self._ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        while True:
            msg = json.loads(self._ws.recv(timeout=60))
            if msg.get("id") == self._id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return dict(msg["result"])

    def screenshot(self) -> np.ndarray:
        data = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        with Image.open(io.BytesIO(data)) as im:
            return np.asarray(im.convert("RGB")).astype(int)

    def close(self) -> None:
        self._ws.close()


@pytest.fixture
def browser() -> Iterator[Any]:
    """Headless Chromium with a fresh profile; yields a function opening a URL in a page."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip(
            "chromium not installed (Debian packages chromium, chromium-driver; make sysdeps)"
        )
    profile = Path(tempfile.mkdtemp(prefix="armcli-chromium-"))
    proc = subprocess.Popen(
        [exe, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "about:blank"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    clients: list[DevTools] = []

    def open_page(url: str) -> DevTools:
        port_file = profile / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not (port_file.exists() and port_file.read_text().strip()):
            if time.monotonic() > deadline or proc.poll() is not None:
                pytest.fail("chromium did not start its DevTools endpoint")
            time.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            page = next(t for t in json.load(r) if t["type"] == "page")
        dev = DevTools(page["webSocketDebuggerUrl"])
        clients.append(dev)
        dev.call("Page.navigate", url=url)
        return dev

    try:
        yield open_page
    finally:
        for dev in clients:
            dev.close()
        proc.kill()
        proc.wait(timeout=10)
        shutil.rmtree(profile, ignore_errors=True)


def colour_masks(img: np.ndarray) -> dict[str, np.ndarray]:
    """The base's blue (0, 0, 0.5) and the forearm's yellow (1, 1, 0), as lit by three.js."""
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return {
        "blue": (b > 60) & (r < 0.3 * b) & (g < 0.3 * b),
        "yellow": (r > 120) & (g > 120) & (b < 0.35 * np.minimum(r, g)),
    }


def wait_for(dev: DevTools, test: Any, timeout: float) -> np.ndarray:
    """Screenshots until `test` passes or `timeout` [s] runs out; returns the last one."""
    deadline = time.monotonic() + timeout
    img = np.zeros((1, 1, 3), dtype=int)
    while True:
        with contextlib.suppress(RuntimeError):  # the page may still be attaching
            img = dev.screenshot()
        if test(img) or time.monotonic() > deadline:
            return img
        time.sleep(0.5)


def save(img: np.ndarray, name: str) -> None:
    """Keep screenshots for people to look at when ARMCLI_SCREENSHOT_DIR is set."""
    out = os.environ.get("ARMCLI_SCREENSHOT_DIR")
    if out:
        Path(out).mkdir(parents=True, exist_ok=True)
        Image.fromarray(img.astype(np.uint8)).save(Path(out) / name)


def test_browser_draws_robot_and_follows_the_api(viewer: Viewer, browser: Any) -> None:
    dev = browser(viewer.url)
    deadline = time.monotonic() + PAINT_TIMEOUT_S
    while not viewer.server.get_clients() and time.monotonic() < deadline:
        time.sleep(0.2)
    assert viewer.server.get_clients(), "the page never connected to the viewer"

    def robot_drawn(img: np.ndarray) -> bool:
        m = colour_masks(img)
        return bool(m["blue"].sum() > MIN_PIXELS and m["yellow"].sum() > MIN_PIXELS)

    home = wait_for(dev, robot_drawn, PAINT_TIMEOUT_S)
    save(home, "viewer_home.png")
    assert home.std() > 10, "the page is blank"
    assert robot_drawn(home), {k: int(v.sum()) for k, v in colour_masks(home).items()}
    row_home = np.nonzero(colour_masks(home)["yellow"])[0].mean()

    viewer.apply_pose("folded")  # the forearm swings from upright to near horizontal (1.5 rad)

    def dropped(img: np.ndarray) -> bool:
        ys = np.nonzero(colour_masks(img)["yellow"])[0]
        return len(ys) > MIN_PIXELS // 3 and ys.mean() - row_home > MIN_DROP_PX

    folded = wait_for(dev, dropped, MOVE_TIMEOUT_S)
    save(folded, "viewer_folded.png")
    assert dropped(folded), "the forearm did not move in the browser"
    assert (np.abs(folded - home).max(axis=-1) > 30).sum() > MIN_PIXELS
