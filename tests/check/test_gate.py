"""`simulate --urdf` refuses what `check` calls an error in the dynamics, and only that."""

from __future__ import annotations

import pytest

from armcli.check.gate import NOT_SIMULATED, refuse_check_errors
from armcli.errors import ModelRefusedError
from armcli.urdf.read import parse_urdf
from tests.helpers import ROOT

ARM = (ROOT / "urdf" / "standalone_arm.urdf").read_text()


def test_the_course_arm_passes() -> None:
    refuse_check_errors(parse_urdf(ARM.encode(), "standalone_arm.urdf"))


def test_a_zero_axis_is_refused_with_checks_rule_id() -> None:
    bad = ARM.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>', 1)
    assert bad != ARM
    with pytest.raises(ModelRefusedError) as exc:
        refuse_check_errors(parse_urdf(bad.encode(), "zero_axis.urdf"))
    assert "axis" in str(exc.value)


def test_a_missing_mesh_does_not_block_the_simulation() -> None:
    """Meshes never enter the dynamics: a mesh-missing error is check's, not simulate's."""
    tail = "</visual>"
    assert tail in ARM
    head, rest = ARM.split("<visual>", 1)
    _body, after = rest.split(tail, 1)
    meshy = (
        head
        + '<visual><geometry><mesh filename="package://nowhere/m.stl"/></geometry>'
        + tail
        + after
    )
    assert "mesh-missing" in NOT_SIMULATED
    refuse_check_errors(parse_urdf(meshy.encode(), "meshy.urdf"))
