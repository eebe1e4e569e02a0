"""`simulate --output run.mcap`, read back by an independent reader (rosbags: its own MCAP
parser and CDR decoder), against the CSV of the same run, the ROS 2 message definitions
rosbags ships, and Pinocchio's forward kinematics for /tf."""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from armcli.errors import InputError
from armcli.sim import job as simjob
from armcli.sim import rosbag
from armcli.sim.options import SimOptions
from armcli.sim.states import FLOAT_FMT, load_replay, write_states
from tests.helpers import DEFAULT_SPEC, ROOT, spec_file

PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
FK_ATOL = 1e-12  # [m] /tf composed vs Pinocchio: round-off only
DURATION = 1.5  # [s] enough for 16 states at the spec's 10 Hz


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """One simulation written as CSV and as MCAP, and the job behind it."""
    job = simjob.prepare(spec_file(DEFAULT_SPEC), SimOptions(trajectory=PICK, duration=DURATION))
    res = simjob.run(job)
    out = tmp_path_factory.mktemp("rosbag")
    rosbag.write_mcap(out / "run.mcap", res, job.rate, job.urdf)
    write_states(out / "run.csv", res, job.rate)
    return {"job": job, "res": res, "mcap": out / "run.mcap", "csv": out / "run.csv"}


def _rosbags_messages(path: Path) -> dict[str, list[tuple[int, Any]]]:
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)  # the standard ROS 2 types, not ours
    out: dict[str, list[tuple[int, Any]]] = {}
    with Reader(path) as reader:
        for conn, t, raw in reader.messages():
            out.setdefault(conn.topic, []).append((t, store.deserialize_cdr(raw, conn.msgtype)))
    return out


def test_joint_states_equal_the_csv_to_the_last_digit(run: dict[str, Any]) -> None:
    msgs = _rosbags_messages(run["mcap"])
    with run["csv"].open() as fh:
        rows = list(csv.DictReader(fh))
    states, refs = msgs[rosbag.JOINT_STATES], msgs[rosbag.REFERENCE]
    assert len(states) == len(refs) == len(rows) == 16  # 0..1.5 s at 10 Hz
    for (t, js), (t_ref, ref), row in zip(states, refs, rows, strict=True):
        assert t == t_ref == round(float(row["time"]) * 1e9)
        assert js.header.stamp.sec * 10**9 + js.header.stamp.nanosec == t
        assert list(js.name) == list(run["res"].joint_names)
        for i, name in enumerate(js.name):
            for field, values in (("position", js.position), ("velocity", js.velocity),
                                  ("effort", js.effort), ("reference", ref.position)):  # fmt: skip
                assert FLOAT_FMT.format(values[i]) == row[f"{name}.{field}"], (t, name, field)


def test_schemas_are_the_ros2_ones_and_rosbag2_metadata(run: dict[str, Any]) -> None:
    from mcap.reader import make_reader
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    with run["mcap"].open("rb") as fh:
        reader = make_reader(fh)
        header = reader.get_header()
        summary = reader.get_summary()
    assert summary is not None and header.profile == "ros2"
    topics = {}
    for ch in summary.channels.values():
        schema = summary.schemas[ch.schema_id]
        assert (schema.encoding, ch.message_encoding) == ("ros2msg", "cdr")
        # Parsed by rosbags, every type in the schema equals rosbags' own ROS 2 definition.
        types = get_types_from_msg(schema.data.decode(), schema.name)
        assert schema.name in types
        for name, (consts, fields) in types.items():
            assert (consts, fields) == tuple(store.fielddefs[name][:2]), name
        (qos,) = yaml.safe_load(ch.metadata["offered_qos_profiles"])
        topics[ch.topic] = (
            schema.name,
            qos["durability"],
            summary.statistics.channel_message_counts[ch.id],
        )
    assert topics == {
        "/joint_states": ("sensor_msgs/msg/JointState", 2, 16),  # 2 = volatile
        "/joint_states_reference": ("sensor_msgs/msg/JointState", 2, 16),
        "/tf": ("tf2_msgs/msg/TFMessage", 2, 16),
        "/tf_static": ("tf2_msgs/msg/TFMessage", 1, 1),  # 1 = transient local, latched
        "/robot_description": ("std_msgs/msg/String", 1, 1),
    }


def test_robot_description_and_tf_match_pinocchio(run: dict[str, Any]) -> None:
    import pinocchio as pin

    job = run["job"]
    msgs = _rosbags_messages(run["mcap"])
    ((_, desc),) = msgs[rosbag.DESCRIPTION]
    assert desc.data == job.urdf.text.decode()
    model = pin.buildModelFromXML(desc.data)
    data = model.createData()
    for (_, tf), (_, js) in zip(msgs[rosbag.TF], msgs[rosbag.JOINT_STATES], strict=True):
        poses = {}
        for ts in tf.transforms:
            tr, rot = ts.transform.translation, ts.transform.rotation
            quat = pin.Quaternion(rot.w, rot.x, rot.y, rot.z)
            pose = pin.SE3(quat.toRotationMatrix(), np.array([tr.x, tr.y, tr.z]))
            poses[ts.child_frame_id] = (ts.header.frame_id, pose)
        q = pin.neutral(model)
        for name, value in zip(js.name, js.position, strict=True):
            q[model.joints[model.getJointId(name)].idx_q] = value
        pin.framesForwardKinematics(model, data, q)
        for link in ("forearm_link", "hand_link"):
            chain, T = link, pin.SE3.Identity()
            while chain in poses:  # compose the /tf edges up to the root link
                parent, pose = poses[chain]
                T, chain = pose * T, parent
            expected = data.oMf[model.getFrameId(link)]
            np.testing.assert_allclose(T.homogeneous, expected.homogeneous, atol=FK_ATOL)


def test_same_run_same_bytes_and_replay(run: dict[str, Any], tmp_path: Path) -> None:
    again = tmp_path / "again.mcap"
    rosbag.write_mcap(again, run["res"], run["job"].rate, run["job"].urdf)
    assert again.read_bytes() == run["mcap"].read_bytes()
    names = list(run["res"].joint_names)
    from_mcap = rosbag.load_replay(run["mcap"], names)
    from_csv = load_replay(run["csv"], names)
    np.testing.assert_allclose(from_mcap.time, from_csv.time, rtol=0, atol=1e-9)
    for name in names:  # the CSV keeps 9 significant digits
        np.testing.assert_allclose(from_mcap.position[name], from_csv.position[name], rtol=1e-8)
        np.testing.assert_allclose(from_mcap.reference[name], from_csv.reference[name], rtol=1e-8)


def test_message_definition_is_rosbag2s_concatenation() -> None:
    text = rosbag.message_definition("sensor_msgs/msg/JointState")
    parts = text.split("\n" + "=" * 80 + "\n")
    # root first, then each dependency depth-first in sorted order, as rosbag2 writes them
    assert [p.splitlines()[0] for p in parts[1:]] == [
        "MSG: std_msgs/Header",
        "MSG: builtin_interfaces/Time",
    ]
    assert "float64[] position" in parts[0]


def test_a_file_that_is_not_mcap_is_an_input_error(tmp_path: Path) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"not an mcap file")
    with pytest.raises(InputError, match="unreadable MCAP file"):
        rosbag.load_replay(bad, ["arm_base_forearm_joint"])


def test_view_replay_takes_an_mcap(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`view --replay X.mcap` goes to the MCAP reader (checked before any server starts)."""
    from armcli.cli import main

    bad = tmp_path / "bad.mcap"
    bad.write_bytes(b"\x89MCAP0\r\n truncated")
    with pytest.raises(SystemExit) as exc:
        main(["view", str(DEFAULT_SPEC), "--replay", str(bad), "--port", "0"])
    assert exc.value.code == 2
    assert f"{bad}: unreadable MCAP file" in capsys.readouterr().err


def test_outputs_are_refused_by_field_before_a_run(tmp_path: Path) -> None:
    spec = tmp_path / "robot.yaml"
    spec.write_text("name: x\n")
    rosbag.check_outputs(tmp_path / "run.mcap", tmp_path / "plot.png", [spec])  # all writable
    for output, plot, field in (
        (tmp_path / "run.txt", None, "output"),  # no writer for .txt
        (spec, None, "output"),  # over an input (issue 42)
        (None, tmp_path / "plot.jpg", "plot"),  # plots are PNG
    ):
        with pytest.raises(InputError) as err:
            rosbag.check_outputs(output, plot, [spec])
        assert err.value.field == field
