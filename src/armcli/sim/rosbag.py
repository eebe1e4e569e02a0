"""`simulate --output run.mcap`: the run as a rosbag2 MCAP file that ROS tools open.

Topics, stamped in simulated time from 0 at the output rate (the CSV's rows, same numbers):

- `/joint_states` (sensor_msgs/msg/JointState): position, velocity, effort of the simulated
  joints;
- `/joint_states_reference` (sensor_msgs/msg/JointState): the position being tracked;
- `/tf` (tf2_msgs/msg/TFMessage): parent -> child of every moving joint;
- `/tf_static` (tf2_msgs/msg/TFMessage): the fixed joints, once (transient local);
- `/robot_description` (std_msgs/msg/String): the simulated URDF, once (transient local).

As rosbag2 records them: MCAP profile `ros2`, schema encoding `ros2msg` with the ROS 2
Jazzy `.msg` texts (armcli/data/ros2_msgs) concatenated the way rosbag2's
LocalMessageDefinitionSource does, message encoding `cdr`, and each channel's
`offered_qos_profiles`. Nothing depends on the wall clock: the same run gives the same bytes.
`load_replay` reads a file back for `view --replay`.
"""

from __future__ import annotations

import dataclasses
import io
import math
import re
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import InputError
from armcli.io.files import write_file_atomic
from armcli.io.mcap_guard import check_chunks
from armcli.io.outdir import check_output_file, check_png_file
from armcli.io.userfile import open_regular
from armcli.robot.frames import axis_quaternion, quaternion_product, rotate, rpy_quaternion
from armcli.robot.joints import rest
from armcli.sim.simulate import SimResult
from armcli.sim.states import TIME, Replay, column, output_format, sample_states
from armcli.spec.joint_types import position_bounds
from armcli.urdf.doc import Joint, Urdf

MCAP_SUFFIX = ".mcap"
PROFILE = "ros2"
SCHEMA_ENCODING = "ros2msg"
MESSAGE_ENCODING = "cdr"
JOINT_STATE = "sensor_msgs/msg/JointState"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
STRING = "std_msgs/msg/String"
JOINT_STATES, REFERENCE = "/joint_states", "/joint_states_reference"
TF, TF_STATIC, DESCRIPTION = "/tf", "/tf_static", "/robot_description"
WORLD = "world"  # a drive's fixed frame: world -> odom -> base is the ground truth
MAX_REPLAY_BYTES = 1_000_000_000
MAX_REPLAY_TRANSFORMS = 10_000_000  # 1 h of the course drive at 50 Hz: 6 a state, 1.1 million


def is_mcap(path: Path) -> bool:
    """Whether `path` names an MCAP file (by its extension)."""
    return path.suffix.lower() == MCAP_SUFFIX


def check_outputs(output: Path | None, plot: Path | None, inputs: Sequence[Path]) -> None:
    """Refuse a run's states file or plot before the run, naming the field.

    A format it cannot write (.csv, .json, .mcap; a plot is PNG), or a path over one of the
    `inputs` (issue 42).
    """
    if output is not None:
        if not is_mcap(output):
            output_format(output)
        check_output_file(output, "output", inputs)
    if plot is not None:
        check_png_file(plot, "plot", inputs)


# -- message definitions, as rosbag2 writes them ---------------------------------------------

_DELIMITER = "=" * 80 + "\n"
_PRIMITIVE = re.compile(r"bool|byte|char|float(32|64)|u?int(8|16|32|64)|string")
_STATE_FIELDS = ("position", "velocity", "effort")
_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")  # rosbag2's regex
_TYPENAME = re.compile(r"^([a-zA-Z0-9_]+)/(?:msg/)?([a-zA-Z0-9_]+)$")


def _msg_text(datatype: str) -> tuple[str, str]:
    """(package, .msg text) of `pkg/msg/Name` or `pkg/Name` from armcli's copies."""
    m = _TYPENAME.match(datatype)
    if m is None:
        raise ValueError(f"not a message type name: {datatype!r}")
    pkg, name = m.groups()
    ref = resources.files("armcli") / "data" / "ros2_msgs" / pkg / "msg" / f"{name}.msg"
    return pkg, ref.read_text(encoding="utf-8")


def _dependencies(text: str, package: str) -> list[str]:
    """Non-primitive field types, package-qualified, sorted (rosbag2's std::set order)."""
    deps = set()
    for m in _FIELD_TYPE.finditer(text):
        name = m.group(1)
        if not _PRIMITIVE.fullmatch(name):
            deps.add(name if "/" in name else f"{package}/{name}")
    return sorted(deps)


def message_definition(datatype: str) -> str:
    """The full text rosbag2 stores as the schema of `datatype` (dependencies appended)."""
    seen: set[str] = set()

    def append(name: str) -> str:
        pkg, text = _msg_text(name)
        out = text
        for dep in _dependencies(text, pkg):
            if dep not in seen:
                seen.add(dep)
                out += "\n" + _DELIMITER + "MSG: " + dep + "\n" + append(dep)
        return out

    return append(datatype)


# -- QoS, as rosbag2 records what a publisher offered (integer enums: bag format <= 8) -------

_INFINITE = {"sec": 9223372036, "nsec": 854775807}  # RMW_DURATION_INFINITE


def qos(depth: int, transient_local: bool) -> str:
    """`offered_qos_profiles` YAML: reliable, keep last `depth`, volatile or transient local."""
    import yaml

    profile = {
        "history": 1,  # KEEP_LAST
        "depth": depth,
        "reliability": 1,  # RELIABLE
        "durability": 1 if transient_local else 2,  # TRANSIENT_LOCAL | VOLATILE
        "deadline": _INFINITE,
        "lifespan": _INFINITE,
        "liveliness": 1,  # AUTOMATIC
        "liveliness_lease_duration": _INFINITE,
        "avoid_ros_namespace_conventions": False,
    }
    return str(yaml.safe_dump([profile], sort_keys=False))


# -- transforms of the URDF's joints --------------------------------------------------------


def joint_transform(j: Joint, value: float) -> tuple[np.ndarray, np.ndarray]:
    """(translation [m], rotation (x, y, z, w)) of the child link in the parent link at `value`."""
    xyz = np.array(j.origin.xyz, dtype=float)
    rot = np.array(rpy_quaternion(j.origin.rpy))
    if j.type == "fixed" or not j.movable:
        return xyz, rot
    axis = np.array(j.axis or (1.0, 0.0, 0.0), dtype=float)
    axis = axis / np.linalg.norm(axis)
    if j.type == "prismatic":
        return xyz + rotate(rot, axis * value), rot
    return xyz, quaternion_product(rot, axis_quaternion(axis, value))


# -- messages --------------------------------------------------------------------------------


def stamp(ns: int) -> dict[str, int]:
    """builtin_interfaces/Time of a time [ns]."""
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _transform(j: Joint, value: float, ns: int) -> dict[str, Any]:
    t, r = joint_transform(j, value)
    return {
        "header": {"stamp": stamp(ns), "frame_id": j.parent},
        "child_frame_id": j.child,
        "transform": {
            "translation": dict(zip("xyz", map(float, t), strict=True)),
            "rotation": dict(zip("xyzw", map(float, r), strict=True)),
        },
    }


def _joint_state(ns: int, names: Sequence[str], **arrays: Sequence[float]) -> dict[str, Any]:
    msg: dict[str, Any] = {"header": {"stamp": stamp(ns), "frame_id": ""}, "name": list(names)}
    for key in ("position", "velocity", "effort"):
        msg[key] = [float(x) for x in arrays.get(key, [])]
    return msg


@dataclass(frozen=True)
class Channel:
    """One topic: its type, QoS and the (log time [ns], message) pairs written on it.

    A message is a dict (serialised by mcap_ros2) or its CDR bytes already (sim.sensors.cdr).
    """

    topic: str
    datatype: str
    qos: str
    messages: list[tuple[int, Any]]  # (log time [ns], a dict or CDR bytes)


def channels(cols: Mapping[str, np.ndarray], names: Sequence[str], urdf: Urdf) -> list[Channel]:
    """Every topic of the file from the sampled states `cols` (sim.states' columns)."""
    stamps = [round(float(t) * 1e9) for t in cols[TIME]]
    state, ref, tf = [], [], []
    tracked = [n for n in names if column(n, "reference") in cols]  # a wheel has no reference
    moving = [j for j in urdf.joints if j.type != "fixed" and j.movable]
    bounds = {j.name: position_bounds(j.type, j.limit) for j in moving}
    resting = {n: rest(*b) if b is not None else 0.0 for n, b in bounds.items()}  # not simulated
    for k, ns in enumerate(stamps):
        values = {n: float(cols[column(n, "position")][k]) for n in names}
        fields = {f: [cols[column(n, f)][k] for n in names] for f in _STATE_FIELDS}
        state.append((ns, _joint_state(ns, names, **fields)))
        reference = [cols[column(n, "reference")][k] for n in tracked]
        ref.append((ns, _joint_state(ns, tracked, position=reference)))
        moved = [_transform(j, values.get(j.name, resting[j.name]), ns) for j in moving]
        tf.append((ns, {"transforms": moved}))
    fixed = [j for j in urdf.joints if j.type == "fixed"]
    start = stamps[0]
    text = urdf.text.decode("utf-8")
    return [
        Channel(DESCRIPTION, STRING, qos(1, True), [(start, {"data": text})]),
        Channel(
            TF_STATIC,
            TF_MESSAGE,
            qos(1, True),
            [(start, {"transforms": [_transform(j, 0.0, start) for j in fixed]})],
        ),
        Channel(JOINT_STATES, JOINT_STATE, qos(10, False), state),
        Channel(REFERENCE, JOINT_STATE, qos(10, False), ref),
        Channel(TF, TF_MESSAGE, qos(100, False), tf),
    ]


def mcap_bytes(chans: Sequence[Channel]) -> bytes:
    """The MCAP file: schemas, channels, then the messages in time order (ties: topic order)."""
    from mcap.writer import CompressionType, Writer
    from mcap_ros2._dynamic import serialize_dynamic

    from armcli import __version__

    buf = io.BytesIO()
    writer = Writer(buf, compression=CompressionType.ZSTD)
    writer.start(profile=PROFILE, library=f"armcli {__version__}")
    schema_ids: dict[str, int] = {}
    encoders: dict[str, Any] = {}
    ids = []
    for ch in chans:
        if ch.datatype not in schema_ids:
            text = message_definition(ch.datatype)
            schema_ids[ch.datatype] = writer.register_schema(
                name=ch.datatype, encoding=SCHEMA_ENCODING, data=text.encode("utf-8")
            )
            encoders[ch.datatype] = serialize_dynamic(ch.datatype, text)[ch.datatype]
        ids.append(
            writer.register_channel(
                topic=ch.topic,
                message_encoding=MESSAGE_ENCODING,
                schema_id=schema_ids[ch.datatype],
                metadata={"offered_qos_profiles": ch.qos},
            )
        )
    for ns, rank, k, msg in sorted(_messages(chans), key=lambda m: m[:3]):
        data = msg if isinstance(msg, bytes) else encoders[chans[rank].datatype](msg)
        writer.add_message(ids[rank], log_time=ns, data=data, publish_time=ns, sequence=k)
    writer.finish()  # type: ignore[no-untyped-call]
    return buf.getvalue()


def _messages(chans: Sequence[Channel]) -> Iterator[tuple[int, int, int, Any]]:
    for rank, ch in enumerate(chans):
        for k, (ns, msg) in enumerate(ch.messages):
            yield ns, rank, k, msg


def run_mcap_bytes(
    res: SimResult, rate: float, urdf: Urdf | None, extra: Sequence[Channel] = ()
) -> bytes:
    """The run sampled at `rate` [Hz] (and `extra` topics) as the bytes of an MCAP file."""
    if urdf is None:
        raise ValueError("an MCAP file needs the simulated robot description")
    cols = sample_states(res, rate)
    return mcap_bytes([*channels(cols, res.joint_names, urdf), *extra])


def write_mcap(path: Path, res: SimResult, rate: float, urdf: Urdf | None) -> None:
    """Write the run sampled at `rate` [Hz] as a rosbag2 MCAP file, atomically."""
    write_file_atomic(path, run_mcap_bytes(res, rate, urdf))


# -- reader ----------------------------------------------------------------------------------


def load_replay(path: str | Path, joints: Sequence[str]) -> Replay:
    """Joint positions (and the reference) over time from a `simulate` MCAP, for `joints`.

    Reads `/joint_states` (and `/joint_states_reference` when present) of any rosbag2 MCAP;
    joints not in `joints` are ignored, as robot_state_publisher does.
    """
    from mcap.exceptions import McapError
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    source = str(path)
    rows: dict[str, list[tuple[float, dict[str, float]]]] = {JOINT_STATES: [], REFERENCE: []}
    bases: dict[int, np.ndarray] = {}
    count = 0
    try:  # a regular file of bounded size (a FIFO blocked open() forever), bounded messages
        with open_regular(path, max_bytes=MAX_REPLAY_BYTES, what="MCAP file") as fh:
            check_chunks(fh, source)  # chunks inflate within a bound, or one error (issue 27)
            reader = make_reader(fh, decoder_factories=[DecoderFactory()])
            for _, channel, _raw, msg in reader.iter_decoded_messages(
                topics=[JOINT_STATES, REFERENCE, TF]
            ):
                if channel.topic == TF:  # a drive's world -> odom -> base: where the robot is
                    count += len(msg.transforms)  # messages are bounded by check_chunks
                    if count > MAX_REPLAY_TRANSFORMS:
                        raise InputError(
                            f"more than {MAX_REPLAY_TRANSFORMS:,} /tf transforms, "
                            "armcli's bound on a replay",
                            file=source,
                        )
                    _collect_base(msg, bases)
                    continue
                t = msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9
                known = {n: float(x) for n, x in zip(msg.name, msg.position, strict=False)}
                mine = {n: v for n, v in known.items() if n in joints}
                bad = [n for n, v in mine.items() if not math.isfinite(v)]
                if bad:
                    raise InputError(
                        f"{channel.topic} at t = {t:g} s: {bad[0]} is not finite", file=source
                    )
                rows[channel.topic].append((t, mine))
    except InputError:
        raise
    except (McapError, OSError, ValueError, KeyError) as exc:
        raise InputError(f"unreadable MCAP file: {exc}", file=source) from None
    except Exception as exc:  # the CDR decoder of a crafted message: struct.error, IndexError...
        why = f"a message does not decode ({type(exc).__name__}: {exc}"[:200] + ")"
        raise InputError(f"unreadable MCAP file: {why}", file=source) from None
    if not rows[JOINT_STATES]:
        raise InputError(f"no {JOINT_STATES} messages", file=source)
    replay = _replay(source, rows[JOINT_STATES], rows[REFERENCE])
    stamps = [round(t * 1e9) for t in replay.time]
    if bases and all(ns in bases for ns in stamps):
        return dataclasses.replace(replay, base=np.array([bases[ns] for ns in stamps]))
    return replay


def _collect_base(msg: Any, bases: dict[int, np.ndarray]) -> None:
    """The root's pose (x, y, z, w, x, y, z) from a /tf message holding world -> A -> B."""
    by_parent = {tr.header.frame_id: tr for tr in msg.transforms}
    first = by_parent.get(WORLD)
    second = by_parent.get(first.child_frame_id) if first is not None else None
    if first is None or second is None:
        return
    p1, q1 = _tf_parts(first.transform)
    p2, q2 = _tf_parts(second.transform)
    p, q = p1 + rotate(q1, p2), quaternion_product(q1, q2)
    values = np.array([*p, q[3], q[0], q[1], q[2]], dtype=float)
    if np.all(np.isfinite(values)):
        stamp = first.header.stamp
        bases[stamp.sec * 1_000_000_000 + stamp.nanosec] = values


def _tf_parts(tr: Any) -> tuple[np.ndarray, np.ndarray]:
    t, r = tr.translation, tr.rotation
    return np.array([t.x, t.y, t.z], dtype=float), np.array([r.x, r.y, r.z, r.w], dtype=float)


def _replay(
    source: str,
    states: list[tuple[float, dict[str, float]]],
    refs: list[tuple[float, dict[str, float]]],
) -> Replay:
    time = np.array([t for t, _ in states])
    if np.any(np.diff(time) <= 0):
        raise InputError(f"{JOINT_STATES} stamps must increase", file=source)
    names = sorted({n for _, v in states for n in v})
    if not names:
        raise InputError(f"{JOINT_STATES} names none of this robot's joints", file=source)
    position = {n: np.array([v.get(n, math.nan) for _, v in states]) for n in names}
    reference: dict[str, np.ndarray] = {}
    if refs:
        at = {round(t * 1e9): v for t, v in refs}
        reference = {
            n: np.array([at.get(round(t * 1e9), {}).get(n, math.nan) for t in time]) for n in names
        }
    return Replay(source=source, time=time, position=position, reference=reference)
