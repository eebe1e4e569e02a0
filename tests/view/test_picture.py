"""`render` as one library call: the picture written, what it noticed returned as lines."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.urdf.source import RobotInput
from armcli.view.picture import render
from tests.helpers import ROOT

REAL = ROOT / "tests" / "fixtures" / "real_robots"


def test_a_missing_texture_comes_back_as_one_warning(tmp_path: Path) -> None:
    """PR2's textured mesh (tests/cli/test_real_robots.py): drawn, one warning, no print."""
    out = tmp_path / "textured.png"
    pic = render(RobotInput((REAL / "textured.urdf",)), out, size=(320, 160))
    assert out.is_file() and Path(pic.result.path) == out
    assert (pic.result.width, pic.result.height) == (320, 160)
    (warning,) = [w for w in pic.warnings if "missing_texture.png" in w]
    assert "meshes/textured.dae" in warning and not warning.startswith("warning: ")


def test_errors_name_the_argument_and_nothing_is_written(tmp_path: Path) -> None:
    spec = RobotInput((ROOT / "specs" / "my_robot.yaml",))
    out = tmp_path / "x.png"
    with pytest.raises(InputError) as err:
        render(spec, out, pose="foldd")
    assert err.value.field == "pose" and not out.exists()
    with pytest.raises(InputError) as err:
        render(spec, tmp_path, q="0,0")  # a directory: refused before the robot is read
    assert err.value.field == "out"
