"""Reach envelope and reachable points: closed forms of a planar two-link arm, urdf-validator.

The course arm is planar (both joints about y): shoulder S at the first joint's origin,
links of 0.3 m, tool point 0.3 m up the hand, both joints in [0, pi/2]. The tool is at
S + 0.3 (sin q1, 0, cos q1) + 0.3 (sin(q1 + q2), 0, cos(q1 + q2)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from armcli.analysis.workspace import REACH_TOL, Chain, envelope, reach_point, sample
from armcli.compiler.expand import expand_urdfs
from armcli.robot.model import Robot
from armcli.robot.tool import ToolPoint
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf
from tests.helpers import DEFAULT_SPEC, ROOT

EXACT = 1e-9  # [m] local search converged onto an extreme
UV = 1e-3  # [m] the agreement with urdf-validator
SHOULDER = np.array([0.15, 0.0, 0.32])  # mount (0.15, 0, 0.2) above base_link at z = 0.1, + 0.02


@pytest.fixture(scope="module")
def model() -> Robot:
    spec = load_spec(DEFAULT_SPEC)
    text = expand_urdfs(spec)["my_robot.urdf"].decode()
    return Robot.load(parse_urdf(text.encode(), "my_robot.urdf"), strict=False)


def tool_at(q1: float, q2: float) -> np.ndarray:
    return (
        SHOULDER
        + 0.3 * np.array([math.sin(q1), 0, math.cos(q1)])
        + 0.3 * np.array([math.sin(q1 + q2), 0, math.cos(q1 + q2)])
    )


def test_envelope_of_the_tool_point(model: Robot) -> None:
    chain = Chain(model, ToolPoint("hand_link", (0.0, 0.0, 0.3)))
    assert [jr.name for jr in chain.joints] == ["arm_base_forearm_joint", "forearm_hand_joint"]
    w = envelope(chain, sample(chain, 200))
    assert w.shoulder == pytest.approx(tuple(SHOULDER), abs=EXACT)
    assert w.max_reach == pytest.approx(0.6, abs=EXACT)  # stretched: 0.3 + 0.3
    assert w.max_height == pytest.approx(SHOULDER[2] + 0.6, abs=EXACT)  # straight up
    assert w.min_height == pytest.approx(tool_at(math.pi / 2, math.pi / 2)[2], abs=EXACT)
    assert w.max_horizontal == pytest.approx(0.15 + 0.6, abs=EXACT)  # stretched forward


def test_reachable_points_and_residuals(model: Robot) -> None:
    chain = Chain(model, ToolPoint("hand_link", (0.0, 0.0, 0.3)))
    cloud = sample(chain, 500)
    inside = tool_at(0.4, 1.1)  # a configuration within the limits
    r = reach_point(chain, cloud, inside)
    assert r.reachable and r.residual < 1e-9
    assert np.allclose(tool_at(*(v for _, v in r.q)), inside, atol=1e-9)
    beyond = SHOULDER + np.array([0.7, 0.0, 0.0])  # 0.7 m > 0.6 m of arm
    r = reach_point(chain, cloud, beyond)
    assert not r.reachable
    assert r.residual == pytest.approx(0.1, abs=1e-6)  # stretched toward it: 0.1 m short
    behind = tool_at(-0.5, 0.3)  # q1 < 0 is outside the limits
    r = reach_point(chain, cloud, behind)
    assert not r.reachable and r.residual > REACH_TOL


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")  # its open()
def test_agrees_with_urdf_validator_on_its_point(model: Robot) -> None:
    """urdf-validator 1.6.0 measures the hand link's origin, not the tool point, and its
    max reach from the arm's mount link origin (0.02 m below the shoulder joint): with the
    same point and centre the numbers agree; armcli's own definitions differ on purpose."""
    pytest.importorskip("urdf_validator_main")
    from urdf_validator_main.checks.workspace import run as run_workspace
    from urdf_validator_main.parser.urdf_adapter import load_urdf
    from urdf_validator_main.report.models import ValidationReport

    path = ROOT / "urdf" / "my_robot.urdf"
    parsed = load_urdf(str(path))
    report = ValidationReport(urdf_path=str(path), robot_name=parsed.name)
    run_workspace(parsed, report)
    chain = Chain(model, ToolPoint("hand_link"))
    cloud = sample(chain, 200)
    w = envelope(chain, cloud)
    assert w.max_height == pytest.approx(report.workspace.vertical_reach, abs=UV)
    assert w.max_horizontal == pytest.approx(report.workspace.horizontal_reach, abs=UV)
    mount = SHOULDER - np.array([0.0, 0.0, 0.02])  # arm_base_link's origin
    theirs = float(np.max(np.linalg.norm(cloud.p - mount, axis=1)))
    assert theirs == pytest.approx(report.workspace.max_reach, abs=UV)
    assert w.max_reach == pytest.approx(0.3, abs=EXACT)  # ours: from the shoulder joint
