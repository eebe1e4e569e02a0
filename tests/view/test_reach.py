"""`render --reach`: the tool point's reachable region drawn over the robot, and its numbers.

The course arm is planar (both joints about y, each in [0, pi/2]): shoulder S at
(0.15, 0, 0.32) in base_footprint, two 0.3 m links, the tool 0.3 m up the hand, so the
tool is at S + 0.3 (sin q1, 0, cos q1) + 0.3 (sin(q1 + q2), 0, cos(q1 + q2)).
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest

from armcli.cli import main
from armcli.compiler.expand import expand_urdfs
from armcli.robot.tool import spec_tool
from armcli.spec.load import load_spec
from armcli.view.png import load_urdf
from armcli.view.reach import REACH_SAMPLES, render_reach_png
from tests.helpers import DEFAULT_SPEC

SHOULDER = np.array([0.15, 0.0, 0.32])
EXACT = 1e-9  # [m] the envelope's refined extremes against the closed form
INSIDE = (0.4, 1.1)  # [rad] a configuration within the limits
REACHABLE_RGB = (0, 128, 0)  # matplotlib "green": the ring of a reached point
MISSED_RGB = (255, 0, 0)  # "red": the cross of a missed one


def tool_at(q1: float, q2: float) -> tuple[float, float, float]:
    p = SHOULDER + 0.3 * np.array([math.sin(q1), 0, math.cos(q1)])
    p = p + 0.3 * np.array([math.sin(q1 + q2), 0, math.cos(q1 + q2)])
    return (float(p[0]), float(p[1]), float(p[2]))


def pixels(png: bytes) -> np.ndarray:
    import matplotlib.image as mpimg

    return np.asarray(mpimg.imread(io.BytesIO(png), format="png"))[:, :, :3] * 255


def count(img: np.ndarray, rgb: tuple[int, int, int], tol: float = 30.0) -> int:
    return int(np.sum(np.all(np.abs(img - np.array(rgb)) < tol, axis=2)))


@pytest.fixture(scope="module")
def course() -> tuple[str, object, object]:
    spec = load_spec(DEFAULT_SPEC)
    xml = expand_urdfs(spec)["my_robot.urdf"].decode()
    return xml, load_urdf(xml, "my_robot.urdf"), spec_tool(spec)


def test_region_numbers_and_points(course, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    xml, urdf, tool = course
    targets = [tool_at(*INSIDE), (SHOULDER[0] + 0.7, 0.0, SHOULDER[2])]  # in; 0.1 m too far
    pic = render_reach_png(urdf, xml, "my_robot.urdf", {}, tmp_path / "r.png", tool=tool,
                           targets=targets, size=(600, 300))  # fmt: skip
    ws = pic.workspace
    assert ws.samples >= REACH_SAMPLES
    assert ws.max_reach == pytest.approx(0.6, abs=EXACT)  # stretched: 0.3 + 0.3
    assert ws.max_height == pytest.approx(SHOULDER[2] + 0.6, abs=EXACT)  # straight up
    assert ws.min_height == pytest.approx(tool_at(math.pi / 2, math.pi / 2)[2], abs=EXACT)
    assert ws.max_horizontal == pytest.approx(SHOULDER[0] + 0.6, abs=EXACT)
    inside, beyond = pic.points
    assert inside.reachable and inside.residual < 1e-6
    assert not beyond.reachable and beyond.residual == pytest.approx(0.1, abs=1e-6)
    assert pic.render.tool_position == pytest.approx(tool_at(0.0, 0.0), abs=EXACT)
    img = pixels(pic.render.path.read_bytes())
    assert img.shape[:2] == (300, 600)
    assert count(img, REACHABLE_RGB) > 5 and count(img, MISSED_RGB) > 5  # both markers drawn


def test_joints_off_the_chain_and_the_pose(course, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """The region does not depend on where the arm is drawn; the wheels do not move it."""
    xml, urdf, tool = course
    pose = {"arm_base_forearm_joint": 0.7, "base_left_wheel_joint": 2.0}
    pic = render_reach_png(urdf, xml, "my_robot.urdf", pose, tmp_path / "r.png", tool=tool,
                           size=(300, 200))  # fmt: skip
    assert pic.workspace.max_reach == pytest.approx(0.6, abs=EXACT)
    assert pic.render.tool_position == pytest.approx(tool_at(0.7, 0.0), abs=EXACT)


def test_cli_reach_and_reach_point(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "reach.png"
    x, y, z = tool_at(*INSIDE)
    args = ["render", str(DEFAULT_SPEC), "-o", str(out), "--size", "400x200"]
    with pytest.raises(SystemExit) as exc:
        main([*args, "--reach-point", f"{x},{y},{z}", "--reach-point", "1,0,0"])
    assert exc.value.code == 0  # a picture: a missed point is news, not a failure
    text = capsys.readouterr().out
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "max 0.600 m from the shoulder (0.150, 0.000, 0.320)" in text
    lines = [ln for ln in text.splitlines() if ln.startswith("point (")]
    assert len(lines) == 2 and ": reachable" in lines[0] and "OUT OF REACH by" in lines[1]

    bad = tmp_path / "bad.png"
    with pytest.raises(SystemExit) as exc:
        main([*args[:2], "-o", str(bad), "--reach-point", "1,0"])
    assert exc.value.code == 2
    assert "--reach-point" in capsys.readouterr().err and not bad.exists()
