"""A robot file is read once and its Robots built once each (issue 38, step 2).

The counts are the done-when of the issue: `simulate` on the course spec builds at most
three Pinocchio models (the arm it runs, the whole robot `check` gates, the floating
robot the balance stands on), a xacro file planned and executed is expanded once, and no
module keeps compiled URDFs between calls (a second read compiles again).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.robot.file import floating_of, robot_of
from armcli.urdf.source import read_robot
from tests.helpers import DEFAULT_SPEC, ROOT, run_main, spec_file

PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
DRIVE = ROOT / "specs" / "trajectories" / "drive.yaml"
ARM_XACRO = ROOT / "urdf" / "standalone_arm.urdf.xacro"  # the course's arm, as a xacro file
BUILDERS = ("buildModelFromXML", "buildModelFromUrdf")  # pinocchio's URDF parsers


def _count_models(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Every Pinocchio model built from a URDF from now on (the builder's name per call)."""
    import pinocchio as pin

    built: list[str] = []
    for name in BUILDERS:
        real = getattr(pin, name)

        def counting(*args: object, _real: object = real, _name: str = name) -> object:
            built.append(_name)
            return _real(*args)  # type: ignore[operator]

        monkeypatch.setattr(pin, name, counting)
    return built


def _count_expansions(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Every safe-mode xacro expansion from now on (the file's name per call)."""
    from armcli.xacro import sandbox

    expanded: list[str] = []
    real = sandbox.run_safe

    def counting(path: Path, *args: object, **kwargs: object) -> object:
        expanded.append(path.name)
        return real(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(sandbox, "run_safe", counting)
    return expanded


def test_simulate_builds_three_models_of_the_course_robot(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    built = _count_models(monkeypatch)
    code, out, _ = run_main(["simulate", DEFAULT_SPEC, "--trajectory", PICK], capsys)
    assert code == 0 and "zero-moment point" in out  # the whole robot's balance was run too
    # the standalone arm (simulated), the whole robot (check's gate), the whole robot on a
    # free-flyer (check's static balance and simulate's zero-moment point share it); 4 before
    assert len(built) <= 3, built


def test_the_drive_builds_three_models_of_the_course_robot(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    built = _count_models(monkeypatch)
    code, _, _ = run_main(
        ["simulate", DEFAULT_SPEC, "--cmd-vel", DRIVE, "--duration", "0.2"], capsys
    )
    assert code == 0
    # the arm (its start pose and reference), the gated whole robot, its floating stance
    # (the check gate's and the drive's); 5 before: the held start pose loaded the arm again
    assert len(built) <= 3, built


def test_a_xacro_file_planned_and_executed_is_expanded_once(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from armcli.plan.execute import execute
    from armcli.plan.request import PlanRequest, plan_request
    from armcli.sim.options import SimOptions

    expanded = _count_expansions(monkeypatch)
    file = read_robot(ARM_XACRO)
    result = plan_request(file, PlanRequest("0,0", "0.5,0.5"))
    done = execute(file, SimOptions(message=result.document.decode(), kp=(50.0,), kd=(5.0,)))
    assert done.joints == result.joints and not done.broken  # it ran what was planned
    assert expanded == [ARM_XACRO.name]  # 2 before: execute read the file again


def test_simulate_expands_a_given_xacro_once(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    expanded = _count_expansions(monkeypatch)
    code, _, _ = run_main(
        ["simulate", DEFAULT_SPEC, "--urdf", ARM_XACRO, "--trajectory", PICK], capsys
    )
    assert code == 0 and expanded == [ARM_XACRO.name]


def test_no_module_keeps_compiled_urdfs(monkeypatch: pytest.MonkeyPatch) -> None:
    """The compiled documents live on the file: reading the spec again compiles again."""
    from armcli.compiler import expand

    calls: list[str] = []
    real = expand.expand_urdfs

    def counting(spec: object, *args: object) -> dict[str, bytes]:
        calls.append(spec.name)  # type: ignore[attr-defined]
        return real(spec, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(expand, "expand_urdfs", counting)
    first, again = spec_file(DEFAULT_SPEC), spec_file(DEFAULT_SPEC)
    assert calls == ["my_robot", "my_robot"]
    assert [u.text for u in first.urdfs] == [u.text for u in again.urdfs]


def test_a_file_builds_each_robot_once() -> None:
    file = spec_file(DEFAULT_SPEC)
    arm = robot_of(file, file.arm)
    assert robot_of(file, file.arm) is arm  # asked again: the same handle
    assert robot_of(file) is not arm and robot_of(file).names != arm.names  # the whole robot
    standing = floating_of(file, file.robot)()
    assert floating_of(file, file.robot)() is standing
    assert standing.model.nq == robot_of(file).model.nq + 7  # on a free-flyer root
    other = spec_file(DEFAULT_SPEC)
    assert robot_of(other, other.arm) is not arm  # another file, its own robots
