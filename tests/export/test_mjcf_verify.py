"""MuJoCo compiles every export before it is written; without MuJoCo the report says so.

The refused case is one the export's own rules do not model (two URDF joints with one
name, which MuJoCo refuses as a repeated name): before, it was written with exit 0.
"""

from __future__ import annotations

import builtins
from pathlib import Path
from typing import Any

import pytest

from armcli.errors import ExportRefusedError
from armcli.export.mjcf_files import export_mjcf

mujoco = pytest.importorskip("mujoco")

BODY = '<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
TWO_JOINTS_ONE_NAME = (
    f'<robot name="r"><link name="base">{BODY}</inertial></link>'
    f'<link name="a">{BODY}</inertial></link><link name="b">{BODY}</inertial></link>'
    f'<joint name="j" type="revolute"><parent link="base"/><child link="a"/>{LIMIT}</joint>'
    f'<joint name="j" type="revolute"><parent link="a"/><child link="b"/>{LIMIT}</joint>'
    "</robot>"
)
ONE_JOINT = (
    f'<robot name="r"><link name="base">{BODY}</inertial></link>'
    f'<link name="a">{BODY}</inertial></link>'
    f'<joint name="j" type="revolute"><parent link="base"/><child link="a"/>{LIMIT}</joint>'
    "</robot>"
)


def test_a_model_mujoco_refuses_is_not_written(tmp_path: Path) -> None:
    (tmp_path / "r.urdf").write_text(TWO_JOINTS_ONE_NAME)
    out = tmp_path / "out" / "robot.xml"
    with pytest.raises(ExportRefusedError, match=r"MuJoCo .* refuses .*repeated name 'j'") as exc:
        export_mjcf(tmp_path / "r.urdf", out)
    assert exc.value.exit_code == 1
    assert not out.parent.exists()


def test_without_mujoco_the_export_says_it_was_not_compiled(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_import = builtins.__import__

    def no_mujoco(name: str, *args: Any, **kw: Any) -> Any:
        if name == "mujoco":
            raise ImportError("No module named 'mujoco'")
        return real_import(name, *args, **kw)

    monkeypatch.setattr(builtins, "__import__", no_mujoco)
    (tmp_path / "r.urdf").write_text(ONE_JOINT)
    res = export_mjcf(tmp_path / "r.urdf", tmp_path / "out" / "robot.xml")
    assert not res.verdict.compiled and "not installed" in res.verdict.text
    assert (tmp_path / "out" / "robot.xml").is_file()


def test_the_verdict_counts_what_mujoco_compiled(tmp_path: Path) -> None:
    (tmp_path / "r.urdf").write_text(ONE_JOINT)
    res = export_mjcf(tmp_path / "r.urdf", tmp_path / "out" / "robot.xml")
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "scene.xml"))
    assert res.verdict.compiled
    assert f"{m.nbody - 1} bodies, {m.nv} degrees of freedom" in res.verdict.text
