"""open_viewer: the panels a robot's inputs allow, refusals before serving, notes as they arise."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.urdf.source import RobotInput
from armcli.view.basepanel import BasePanel, MobileViewer
from armcli.view.launch import ViewRequest, open_viewer
from armcli.view.panel import PlanningPanel
from tests.helpers import DEFAULT_SPEC


def test_the_course_robot_gets_both_panels_and_closes(tmp_path: Path) -> None:
    said: list[str] = []
    app = open_viewer(
        RobotInput((DEFAULT_SPEC,)), ViewRequest(port=0, save_dir=tmp_path), said.extend
    )
    try:
        # the course robot has a planned arm and a diff drive (specs/my_robot.yaml)
        assert isinstance(app.viewer, MobileViewer)
        assert [type(p) for p in app.panels] == [PlanningPanel, BasePanel]
        assert app.viewer.url.startswith("http://127.0.0.1:")
    finally:
        app.close()


@pytest.mark.parametrize(
    ("request_", "field"),
    [
        (ViewRequest(port=70000), "port"),
        (ViewRequest(port=0, save_dir=Path("/no/such")), "save_dir"),
    ],
)
def test_refusals_name_the_field_before_any_server(request_: ViewRequest, field: str) -> None:
    said: list[str] = []

    def say(lines: Iterable[str]) -> None:
        said.extend(lines)

    with pytest.raises(InputError) as exc:
        open_viewer(RobotInput((DEFAULT_SPEC,)), request_, say)
    assert exc.value.field == field


def test_a_robot_without_joints_gets_no_panel_and_a_note(tmp_path: Path) -> None:
    urdf = tmp_path / "block.urdf"  # one link, nothing to plan for
    urdf.write_text(
        '<robot name="block"><link name="base"><visual><geometry><box size="0.1 0.1 0.1"/>'
        "</geometry></visual></link></robot>\n"
    )
    said: list[str] = []
    app = open_viewer(RobotInput((urdf,)), ViewRequest(port=0, save_dir=tmp_path), said.extend)
    app.close()
    assert app.panels == []
    assert any(line.startswith("note: no planning panel: ") for line in said), said
