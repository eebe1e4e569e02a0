"""`plan` as one library call: refusals before planning, the file written, the run."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.errors import InputError
from armcli.plan.api import PlanOptions
from armcli.plan.request import PlanRequest
from armcli.plan.run import plan
from armcli.urdf.source import RobotInput
from tests.helpers import ROOT

SPEC = ROOT / "specs" / "my_robot.yaml"
ARM = ROOT / "urdf" / "standalone_arm.urdf"


def test_an_output_over_an_input_is_refused_before_planning(tmp_path: Path) -> None:
    heard: list[str] = []
    with pytest.raises(InputError) as err:
        plan(
            RobotInput((SPEC,)),
            PlanRequest(goal="reach"),
            PlanOptions(),
            output=SPEC,
            warn=heard.append,
        )
    assert err.value.field == "output" and heard == []


def test_a_urdf_without_gains_is_not_planned_to_be_run(tmp_path: Path) -> None:
    out = tmp_path / "plan.yaml"
    with pytest.raises(InputError) as err:
        plan(
            RobotInput(), PlanRequest(goal="0.3,0.3"), PlanOptions(), urdf=ARM, output=out, run=True
        )
    assert err.value.field == "execute" and not out.exists()  # nothing written


def test_the_plan_is_written_and_run(tmp_path: Path) -> None:
    out = tmp_path / "plan.yaml"
    heard: list[str] = []
    done = plan(
        RobotInput((SPEC,)),
        PlanRequest(goal="reach"),
        PlanOptions(seed=1),
        output=out,
        run=True,
        warn=heard.append,
    )
    assert done.what == "from home to reach" and heard == []
    assert out.read_bytes() == done.result.document
    assert b"joint_names:" in out.read_bytes() and done.result.joints
    assert done.executed is not None and not done.executed.broken
