"""The joint-type facts of `armcli.urdf.doc`: degrees of freedom and position bounds."""

from __future__ import annotations

import pytest

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.robot.load import load_model
from armcli.spec.joint_types import position_bounds, total_dof
from armcli.spec.model import Limit as SpecLimit
from armcli.urdf.doc import Limit
from armcli.urdf.read import parse_urdf


def _link(name: str) -> str:
    return (
        f'<link name="{name}"><inertial><mass value="1"/>'
        '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>'
    )


def _joint(name: str, kind: str, parent: str, child: str) -> str:
    limit = '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<axis xyz="0 0 1"/>{limit}</joint>'
    )


# One joint of each type in a chain: 0 + 6 + 3 + 1 + 1 + 1 = 12 degrees of freedom.
KINDS = ("fixed", "floating", "planar", "revolute", "continuous", "prismatic")
URDF = (
    '<robot name="every_type">'
    + "".join(_link(f"l{i}") for i in range(len(KINDS) + 1))
    + "".join(_joint(f"j{i}", k, f"l{i}", f"l{i + 1}") for i, k in enumerate(KINDS))
    + "</robot>"
)


def test_dof_counts_every_joint_type_as_pinocchio_does() -> None:
    doc = parse_urdf(URDF.encode(), "every_type.urdf")
    model = load_model(doc.source, xml=URDF).model
    # Pinocchio is the independent reference: its tangent space has one entry per DoF.
    assert total_dof(j.type for j in doc.joints) == model.nv == 12
    summary = check_urdf(doc, CheckOptions()).summary
    assert summary.dof == model.nv  # check's summary asks the same function


def test_unknown_joint_type_adds_no_dof() -> None:
    assert total_dof(["revolute", "hinge"]) == 1  # "hinge" is reported as joint-type


def test_position_bounds_of_bounded_and_unbounded_joints() -> None:
    lim = Limit(-1.0, 2.0, 10.0, 1.0, None)
    assert position_bounds("revolute", lim) == (-1.0, 2.0)
    assert position_bounds("prismatic", lim) == (-1.0, 2.0)
    assert position_bounds("continuous", lim) is None  # URDF ignores its lower/upper
    assert position_bounds("revolute", None) is None
    assert position_bounds("revolute", Limit(None, 2.0, 10.0, 1.0, None)) is None


def test_position_bounds_reads_a_spec_limit_too() -> None:
    lim = SpecLimit(lower=0.0, upper=1.5, effort=5.0, velocity=1.0)
    assert position_bounds("revolute", lim) == (0.0, 1.5)
    assert position_bounds("continuous", lim) is None


@pytest.mark.parametrize("kind", ["fixed", "floating", "planar"])
def test_joints_that_are_not_one_axis_are_not_movable(kind: str) -> None:
    doc = parse_urdf(URDF.encode(), "every_type.urdf")
    assert not next(j for j in doc.joints if j.type == kind).movable
