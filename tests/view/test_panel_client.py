"""What a page may send the planning panel, sent by a real WebSocket client (issue 42).

viser applies a client's GuiUpdateMessage to a widget without checking it against the
widget's options, so any value can arrive. Before: a Goal set to a name not among the
dropdown's options logged a traceback and left the status unchanged; Save with a NUL byte
or a 5,000-character name never answered; Save replaced `roots-notes.yaml`, a file the
viewer had not written. Now each answers in the status line and the viewer stays alive.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import viser

from armcli.view.browser import Viewer
from armcli.view.panel import PlanningPanel
from armcli.view.planning import load_session
from armcli.view.scene import load_robot

TIMEOUT_S = 30.0  # a plan on a loaded 2-core machine


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


class Page:
    """A WebSocket client holding the viewer's token, speaking viser's messages.

    viser counts a client as connected (and runs widget callbacks for it) once the page
    has sent its first camera message, so that comes first, as from a browser.
    """

    def __init__(self, viewer: Viewer) -> None:
        from viser import _messages
        from websockets.sync.client import connect

        self.ws = connect(
            f"ws://127.0.0.1:{viewer.port}/?token={viewer.token}",
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            open_timeout=TIMEOUT_S,
        )
        self.send(_messages.ViewerCameraMessage(
            wxyz=(1.0, 0.0, 0.0, 0.0), position=(2.0, 0.0, 1.0), fov=1.0, near=0.01, far=100.0,
            image_height=600, image_width=800, look_at=(0.0, 0.0, 0.5),
            up_direction=(0.0, 0.0, 1.0),
        ))  # fmt: skip
        deadline = time.monotonic() + TIMEOUT_S
        while not viewer.server.get_clients() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert viewer.server.get_clients(), "the viewer never took the client in"

    def send(self, msg: Any) -> None:
        import msgspec

        self.ws.send(msgspec.msgpack.encode(msg.as_serializable_dict()))

    def set(self, widget: Any, value: object) -> None:
        """What the page sends when a widget changes (a click is value True)."""
        from viser import _messages

        self.send(_messages.GuiUpdateMessage(uuid=widget._impl.uuid, updates={"value": value}))

    def close(self) -> None:
        self.ws.close()


def _say(panel: PlanningPanel, page: Page, widget: Any, value: object) -> str:
    """Send a widget change; the status line the panel answers with."""
    panel._set_status("waiting")  # every answer differs from this
    page.set(widget, value)
    deadline = time.monotonic() + TIMEOUT_S
    while panel.status in ("waiting", "planning...") and time.monotonic() < deadline:
        time.sleep(0.05)
    return panel.status


def test_a_pose_name_not_offered_answers_unknown_pose(panel: PlanningPanel) -> None:
    page = Page(panel.viewer)
    try:
        goal = panel.session.goal.copy()
        said = _say(panel, page, panel._goal_box, "no-such-pose")
        assert said.startswith("not changed: unknown pose 'no-such-pose'; valid: "), said
        said = _say(panel, page, panel._start_box, "also-not")
        assert said.startswith("not changed: unknown pose 'also-not'"), said
        assert (panel.session.goal == goal).all()
        assert _say(panel, page, panel._plan_button, True).startswith("planned: ")  # alive
    finally:
        page.close()


def test_save_answers_for_every_name_and_asks_before_replacing(panel: PlanningPanel) -> None:
    notes = panel.session.save_dir / "roots-notes.yaml"
    notes.write_text("root's notes\n")
    page = Page(panel.viewer)
    try:
        assert _say(panel, page, panel._plan_button, True).startswith("planned: ")
        for name, why in [
            ("a\0b.yaml", "control characters or NUL"),
            ("x" * 5000 + ".yaml", "too long"),
            ("roots-notes.yaml", "exists and this viewer did not write it"),
        ]:
            page.set(panel._file_box, name)
            said = _say(panel, page, panel._save_button, True)
            assert said.startswith("not saved: ") and why in said, said
        assert notes.read_text() == "root's notes\n"
        page.set(panel._overwrite_box, True)  # the confirmation, in the panel
        said = _say(panel, page, panel._save_button, True)
        assert said == f"wrote {notes}", said
        assert notes.read_bytes() == panel.session.result.document
        assert panel._overwrite_box.value is False  # asked again next time
    finally:
        page.close()
