"""Launch templates: substituted values are plain names, and the result must compile."""

from __future__ import annotations

import ast

import pytest

from armcli.errors import BuildError
from armcli.ros.launch import module_constants, render

VALUES = {
    "description_pkg": "robot_description",
    "bringup_pkg": "robot_bringup",
    "robot_xacro": "robot.urdf.xacro",
    "standalone_xacro": "standalone_arm.urdf.xacro",
    "robot_root": "base_footprint",
    "standalone_root": "arm_base_link",
    "rviz_config": "display.rviz",
    "gazebo_launch": "robot_gazebo.launch.py",
    "entity": "robot",
}


def test_render_substitutes_names_into_module_constants() -> None:
    text = render("display.launch.py.tmpl", VALUES, "note")
    consts = module_constants(ast.parse(text))
    assert consts["DESCRIPTION_PKG"] == "robot_description"
    assert consts["ROBOT_XACRO"] == "robot.urdf.xacro"
    assert consts["RVIZ_CONFIG"] == "display.rviz"
    assert b"$" not in text  # every placeholder was filled


def test_values_that_could_inject_code_are_refused() -> None:
    for bad in ('x"; import os; "', "a b", "name'"):
        with pytest.raises(BuildError, match="unsafe value"):
            render("display.launch.py.tmpl", {**VALUES, "entity": bad})


def test_missing_value_is_a_build_error() -> None:
    values = {k: v for k, v in VALUES.items() if k != "robot_root"}
    with pytest.raises(BuildError, match="missing value"):
        render("display.launch.py.tmpl", values)


def test_free_text_note_cannot_close_the_docstring() -> None:
    text = render("display.launch.py.tmpl", VALUES, 'evil """ note')
    ast.parse(text)  # the quotes were replaced, the module still parses
