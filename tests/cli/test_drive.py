"""`armcli simulate SPEC --cmd-vel`: the files it writes, read back, and the inputs it refuses.

The MCAP is read by rosbags (its own MCAP parser and CDR decoder, ROS 2 Jazzy's message
definitions) and compared with the CSV of the same run.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import DEFAULT_SPEC, ROOT, SPECS, run_main

pytest.importorskip("mujoco")

PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
DRIVE = ROOT / "specs" / "trajectories" / "drive.yaml"
DURATION = "3.0"  # [s] 151 states at the plugin's 50 Hz


def _rosbags(path: Path) -> dict[str, list[tuple[int, Any]]]:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    out: dict[str, list[tuple[int, Any]]] = {}
    with Reader(path) as reader:
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, store.deserialize_cdr(raw, conn.msgtype)))
    return out


@pytest.fixture(scope="module")
def drive_files(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("drive")
    files = {"mcap": out / "run.mcap", "csv": out / "run.csv", "png": out / "run.png"}
    from armcli.cli import main

    for key in ("mcap", "csv"):
        args = ["simulate", DEFAULT_SPEC, "--cmd-vel", DRIVE, "-t", PICK, "--duration", DURATION,
                "-o", files[key]]  # fmt: skip
        if key == "csv":
            args += ["--plot", files["png"]]
        try:
            main([str(a) for a in args])
        except SystemExit as exc:
            assert not exc.code
    return files


def test_mcap_has_the_drive_topics_and_equals_the_csv(drive_files: dict[str, Path]) -> None:
    msgs = _rosbags(drive_files["mcap"])
    with drive_files["csv"].open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == len(msgs["/odom"]) == len(msgs["/joint_states"]) == 151
    assert [m.linear.x for _, m in msgs["/cmd_vel"]] == [0.3, 0.0]  # the commands up to 3 s
    for (t, odom), (_, js), (_, tf), row in zip(msgs["/odom"], msgs["/joint_states"],
                                                msgs["/tf"], rows, strict=True):  # fmt: skip
        assert t == round(float(row["time"]) * 1e9)
        assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
        assert f"{odom.pose.pose.position.x:.9g}" == row["odom.x"]
        assert f"{odom.pose.pose.position.y:.9g}" == row["odom.y"]
        assert "base_left_wheel_joint" in js.name and "base_right_wheel_joint" in js.name
        i = list(js.name).index("base_left_wheel_joint")
        assert f"{js.position[i]:.9g}" == row["base_left_wheel_joint.position"]
        frames = {(x.header.frame_id, x.child_frame_id): x.transform for x in tf.transforms}
        assert ("odom", "base_footprint") in frames and ("world", "odom") in frames
    # world -> odom -> base_footprint is the ground truth: at the end, the CSV's base.x
    last = msgs["/tf"][-1][1].transforms
    w_o = next(x.transform for x in last if x.child_frame_id == "odom")
    o_b = next(x.transform for x in last if x.child_frame_id == "base_footprint")
    import numpy as np

    def mat(tr: Any) -> np.ndarray:
        from scipy.spatial.transform import Rotation

        T = np.eye(4)
        r = tr.rotation
        T[:3, :3] = Rotation.from_quat([r.x, r.y, r.z, r.w]).as_matrix()
        T[:3, 3] = (tr.translation.x, tr.translation.y, tr.translation.z)
        return T

    T = mat(w_o) @ mat(o_b)
    assert T[0, 3] == pytest.approx(float(rows[-1]["base.x"]), abs=1e-6)
    assert T[1, 3] == pytest.approx(float(rows[-1]["base.y"]), abs=1e-6)


def test_mcap_schemas_are_rosbags_ros2_definitions(drive_files: dict[str, Path]) -> None:
    from mcap.reader import make_reader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)  # the standard ROS 2 types, not ours
    with drive_files["mcap"].open("rb") as fh:
        summary = make_reader(fh).get_summary()
    assert summary is not None
    names = {s.name for s in summary.schemas.values()}
    assert {"nav_msgs/msg/Odometry", "geometry_msgs/msg/Twist"} <= names
    for schema in summary.schemas.values():
        types = get_types_from_msg(schema.data.decode(), schema.name)
        for name, (consts, fields) in types.items():
            assert (consts, fields) == tuple(store.fielddefs[name][:2]), name


def test_csv_columns_and_the_plot(drive_files: dict[str, Path]) -> None:
    with drive_files["csv"].open() as fh:
        header = next(csv.reader(fh))
    base = [f"base.{c}" for c in ("x", "y", "z", "roll", "pitch", "yaw")]
    odom = ["odom.x", "odom.y", "odom.yaw"]
    loads = ["caster_wheel_link.normal_force", "base_right_wheel_link.normal_force"]
    for name in (*base, *odom, "base_left_wheel_joint.effort", *loads):
        assert name in header
    assert drive_files["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("commands:\n  - {linear: {x: 0.2}, velocity: 1}\n", ":2 commands[0].velocity"),
        ("commands:\n  - {linear: {x: .nan}}\n", ":2 commands[0].linear.x"),
        ("commands:\n  - {time_from_start: 2}\n  - {time_from_start: 1}\n",
         ":3 commands[1].time_from_start"),
    ],
)  # fmt: skip
def test_bad_cmd_vel_is_exit_2_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, where: str
) -> None:
    cmd = tmp_path / "bad.yaml"
    cmd.write_text(text)
    out = tmp_path / "run.mcap"
    code, _, err = run_main(["simulate", DEFAULT_SPEC, "--cmd-vel", cmd, "-o", out], capsys)
    assert code == 2
    assert f"{cmd}{where}" in err
    assert not out.exists()


def test_a_robot_without_a_diff_drive_is_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run.csv"
    code, _, err = run_main(
        ["simulate", SPECS / "tabletop_arm.yaml", "--cmd-vel", DRIVE, "-o", out], capsys
    )
    assert code == 2 and "mobile_base.diff_drive" in err
    assert not out.exists()


def test_a_robot_check_says_tips_is_refused_unless_ignored_then_tips(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    heavy = tmp_path / "heavy_hand.yaml"  # a 10 kg hand: tests/drive/test_job.py
    text = DEFAULT_SPEC.read_text()
    heavy.write_text(text.replace("      material: orange\n      mass: 0.3\n",
                                  "      material: orange\n      mass: 10.0\n"))  # fmt: skip
    forward = tmp_path / "forward.yaml"
    forward.write_text("joint_names: [arm_base_forearm_joint, forearm_hand_joint]\n"
                       "points:\n - {positions: [1.5, 0.0], time_from_start: 2.0}\n")  # fmt: skip
    still = tmp_path / "still.yaml"
    still.write_text("commands:\n  - {time_from_start: 0}\n")
    out = tmp_path / "run.mcap"
    args = ["simulate", heavy, "--cmd-vel", still, "-t", forward, "--gravity-comp",
            "--duration", "2.5", "-o", out]  # fmt: skip
    code, _, err = run_main(args, capsys)
    assert code == 2 and "com-outside-support" in err and "--ignore com-outside-support" in err
    assert not out.exists()
    code, stdout, err = run_main([*args, "--ignore", "com-outside-support"], capsys)
    assert code == 1 and "the robot tips over" in err and "TIPS OVER" in stdout
    assert out.exists()  # the run is written: open it to watch the robot fall


def test_replay_moves_the_base_from_either_file(drive_files: dict[str, Path]) -> None:
    from armcli.sim import rosbag
    from armcli.sim.states import load_replay
    from armcli.view.browser import Viewer
    from armcli.view.scene import load_robot

    with drive_files["csv"].open() as fh:
        last = list(csv.DictReader(fh))[-1]
    robot = load_robot(DEFAULT_SPEC)
    joints = ["arm_base_forearm_joint", "forearm_hand_joint", "base_left_wheel_joint",
              "base_right_wheel_joint"]  # fmt: skip
    for run in (load_replay(drive_files["csv"], joints),
                rosbag.load_replay(drive_files["mcap"], joints)):  # fmt: skip
        end = run.base_at(float(run.time[-1]))
        assert end is not None
        assert end[0][:2] == pytest.approx([float(last["base.x"]), float(last["base.y"])],
                                           abs=1e-6)  # fmt: skip
        assert abs(end[0][0]) > 0.5  # it drove 0.6 m and more
        with Viewer(robot.xml, tool=robot.tool, replay=run, port=0) as v:
            v.seek(float(run.time[-1] - run.time[0]))
            assert v._base is not None
            assert tuple(v._base.position)[:2] == pytest.approx(tuple(end[0][:2]), abs=1e-6)
            # a wheel turns on: its angle is shown wrapped to ±pi, not stuck at the slider's end
            wheel = float(run.position["base_left_wheel_joint"][-1])
            assert abs(wheel) > 2 * math.pi  # more than a turn
            shown = v.configuration()["base_left_wheel_joint"]
            assert shown == pytest.approx((wheel + math.pi) % (2 * math.pi) - math.pi, abs=1e-9)


@pytest.mark.parametrize(
    ("text", "where"),
    [
        ("collision_objects:\n  - id: wall\n    primitives: [{type: box, dimensions: [1, 1]}]\n"
         "    primitive_poses: [{}]\n", ":3 collision_objects[0].primitives[0].dimensions"),
        ("collision_objects:\n  - id: wall\n    header: {frame_id: nowhere}\n"
         "    primitives: [{type: sphere, dimensions: [0.1]}]\n    primitive_poses: [{}]\n",
         ":3 collision_objects[0].header.frame_id"),
    ],
)  # fmt: skip
def test_bad_world_is_exit_2_naming_file_and_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, where: str
) -> None:
    world = tmp_path / "world.yaml"
    world.write_text(text)
    out = tmp_path / "run.mcap"
    args = ["simulate", DEFAULT_SPEC, "--cmd-vel", DRIVE, "--world", world, "-o", out]
    code, _, err = run_main(args, capsys)
    assert code == 2
    assert f"{world}{where}" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_world_in_an_arm_run_is_read_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # what an arm's sensors see (sim.sensors.armsense): read, and refused as in a drive
    world = tmp_path / "world.yaml"
    world.write_text("collision_objects:\n  - id: wall\n    primitives: [{type: box}]\n"
                     "    primitive_poses: [{}]\n")  # fmt: skip
    code, _, err = run_main(["simulate", DEFAULT_SPEC, "-t", PICK, "--world", world], capsys)
    assert code == 2 and f"{world}:3 collision_objects[0].primitives[0].dimensions" in err


@pytest.mark.parametrize("duration", ["0", "-1"])
def test_a_drive_of_no_time_is_refused_like_any_run(duration: str, tmp_path: Path) -> None:
    """Issue 42: `--duration 0` with `--cmd-vel` ran a drive of 0 s and wrote its files."""
    from tests.helpers import run_cli

    out = tmp_path / "run.csv"
    args: list[str | Path] = ["simulate", DEFAULT_SPEC, "--cmd-vel", DRIVE, "--duration", duration]
    proc = run_cli([*args, "-o", out], tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr == f"error: --duration: must be in (0, 3600] s, got {duration}\n"
    assert not out.exists()
