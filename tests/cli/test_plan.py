"""`armcli plan` through the real command: plan, then simulate the file; failures and bad input."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.helpers import DEFAULT_SPEC, FIXTURES, run_main

BOX = FIXTURES / "plan" / "box_in_the_way.yaml"
POST = FIXTURES / "plan" / "post_cuts_off.yaml"  # tests/plan/test_diagnose.py's band
SHELF = FIXTURES / "plan" / "shelf_at_reach.yaml"


def plan(args: list[str | Path], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    return run_main(["plan", DEFAULT_SPEC, *args], capsys)


def test_plan_home_to_reach_then_simulate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out_file = tmp_path / "t.yaml"
    code, out, err = plan(["--from", "home", "--to", "reach", "-o", out_file], capsys)
    assert code == 0, err
    assert f"wrote {out_file}" in out
    assert all(len(line) <= 80 for line in out.splitlines())
    code, out, err = run_main(["simulate", DEFAULT_SPEC, "--trajectory", out_file], capsys)
    assert code == 0, err
    assert "forearm_hand_joint" in out


def test_plan_around_a_box_json_and_same_bytes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    files = [tmp_path / "a.yaml", tmp_path / "b.yaml"]
    for f in files:
        code, out, err = plan(["--to", "reach", "--scene", BOX, "--seed", "2", "--format",
                               "json", "-o", f], capsys)  # fmt: skip
        assert code == 0, err
        doc = json.loads(out)
        assert doc["status"] == "planned" and doc["output"] == str(f)
        assert doc["waypoints"] > 2  # around the box, not straight through it
        assert doc["duration_s"] > 0 and doc["path_length_rad"] > 1.1107  # > straight line
    assert files[0].read_bytes() == files[1].read_bytes()


def test_execute_reports_tracking_and_effort(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = plan(["--to", "reach", "--execute", "--format", "json"], capsys)
    assert code == 0, err
    done = json.loads(out)["execute"]
    assert not done["broken"]
    assert set(done["peak_effort"]) == {"arm_base_forearm_joint", "forearm_hand_joint"}
    assert done["tip_margin_m"] > 0  # the course arm on its mobile base stays upright


def test_start_in_collision_names_link_and_object(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out_file = tmp_path / "t.yaml"
    # q = (0.4, 0.3): the hand crosses the box (tests/plan/test_api.py's independent check)
    code, _, err = plan(["--from", "0.4,0.3", "--to", "reach", "--scene", BOX, "-o",
                           out_file], capsys)  # fmt: skip
    assert code == 1
    assert err.strip().splitlines() == ["error: start is in collision: hand_link and box"]
    assert not out_file.exists()


def test_failure_as_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = plan(["--to-xyz", "3,0,0.5", "--format", "json"], capsys)
    assert code == 1
    doc = json.loads(out)
    assert doc["status"] == "failed" and doc["output"] is None
    assert "closest" in doc["reason"]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["--to", "nowhere"], "--to: unknown pose 'nowhere'"),
        (["--to", "0.1,0.2,0.3"], "--to: expected 2 value(s)"),
        (["--to", "reach", "--to-xyz", "1,2,3"], "--to: give exactly one goal"),
        (["--to-xyz", "1,2"], "--to-xyz: expected x,y,z in metres"),
        (["--to", "reach", "--joints", "wheel"], "--joints: unknown joint 'wheel'"),
        (["--to", "reach", "--planner", "prm"], "--planner: unknown value 'prm'"),
    ],
)
def test_bad_input_exit_2(
    args: list[str | Path], words: str, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = plan(args, capsys)
    assert code == 2
    assert words in err and len(err.strip().splitlines()) == 1


def test_bad_scene_names_file_and_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "collision_objects:\n  - id: a\n    primitives: [{type: 7}]\n    primitive_poses: [{}]\n"
    )
    code, _, err = plan(["--to", "reach", "--scene", scene], capsys)
    assert code == 2
    assert f"{scene}:3 collision_objects[0].primitives[0].type: unknown primitive 7" in err


def test_plan_for_a_urdf(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out_file = tmp_path / "t.yaml"
    urdf = FIXTURES / "plan" / "two_link.urdf"  # no poses: --from is required
    code, _, err = run_main(["plan", "--urdf", urdf, "--to", "1,0"], capsys)
    assert code == 2 and "--from" in err and "named pose: none" in err
    srdf = tmp_path / "two_link.srdf"  # a pose named otherwise (example-robot-data's Panda)
    srdf.write_text(
        '<robot name="two_link"><group name="arm"><joint name="shoulder"/><joint name="elbow"/>'
        '</group><group_state name="ready" group="arm"><joint name="shoulder" value="0"/>'
        '<joint name="elbow" value="0.5"/></group_state></robot>\n'
    )
    code, _, err = run_main(["plan", "--urdf", urdf, "--srdf", srdf, "--to", "1,0"], capsys)
    assert code == 2 and "--from" in err and "named pose: ready" in err, err
    args = ["plan", "--urdf", urdf, "--from", "0,0", "--to", "1.0,-0.5", "-o", out_file]
    code, out, err = run_main(args, capsys)
    assert code == 0, err
    assert "joints: shoulder, elbow" in out and out_file.is_file()


def test_execute_of_a_urdf_is_refused_before_planning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A URDF has no gains to simulate with: refused up front, no plan file left behind."""
    out_file = tmp_path / "t.yaml"
    urdf = FIXTURES / "plan" / "two_link.urdf"
    args = ["plan", "--urdf", urdf, "--from", "0,0", "--to", "1.0,-0.5", "--execute", "-o",
            out_file]  # fmt: skip
    code, _, err = run_main(args, capsys)
    assert code == 2 and not out_file.exists()
    assert err.count("error:") == 1 and "--execute" in err and "armcli import" in err, err
    assert "SimOptions" not in err


def test_pi_values_and_a_limit_typed_as_printed(capsys: pytest.CaptureFixture[str]) -> None:
    """The spec's `pi/2` works in --to; 1.5708 (pi/2 as printed) is the stop, with a note."""
    code, out, err = plan(["--to", "pi/2,pi/4"], capsys)
    assert code == 0, err
    code, out, err = plan(["--to", "1.5708,0", "--format", "json"], capsys)
    assert code == 0, err
    (note,) = json.loads(out)["notes"]
    assert "arm_base_forearm_joint = 1.5708 is taken as its upper limit" in note


def test_a_goal_point_inside_an_object_names_what_collides(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, _, err = plan(["--to-xyz", "0.662,0,0.532", "--scene", SHELF], capsys)
    assert code == 1
    assert "only in collision: hand_link and shelf" in err


def test_a_cut_off_goal_is_not_a_timeout(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = plan(["--to", "reach", "--scene", POST, "--timeout", "0.2"], capsys)
    assert code == 1
    assert "the goal is cut off from the start" in err and "will not help" in err


def test_the_summary_says_what_was_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = plan(["--to", "reach"], capsys)
    assert code == 0, err
    assert out.splitlines()[-1].startswith("not written: no -o FILE given")
    out_file = tmp_path / "t.yaml"
    out_file.write_text("old")
    code, out, err = plan(["--to", "reach", "-o", out_file], capsys)
    assert code == 0, err
    assert out.splitlines()[-1] == f"replaced {out_file}"  # never silently


def test_rpy_in_degrees_is_warned_about(capsys: pytest.CaptureFixture[str]) -> None:
    _, _, err = plan(["--to-xyz", "0.6,0,0.5", "--to-rpy", "0,90,0", "--timeout", "0.2"], capsys)
    assert "warning: roll, pitch, yaw 0,90,0 look like degrees" in err
    assert "1.571" in err


@pytest.mark.parametrize(
    ("command", "args"),
    [
        ("plan", [DEFAULT_SPEC, "--to", "0.1,0.2,0.3"]),
        ("plan", [DEFAULT_SPEC, "--to-xyz", "1,2"]),
        ("check", [DEFAULT_SPEC, "--ignore", "no-such-rule"]),
    ],
)
def test_bad_input_as_json_on_stdout(
    command: str, args: list[str | Path], capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run_main([command, *args, "--format", "json"], capsys)
    assert code == 2 and err.startswith("error: ")
    doc = json.loads(out)
    assert doc["status"] == "error" and doc["exit_code"] == 2
    assert doc["reason"] == err.strip().removeprefix("error: ")
