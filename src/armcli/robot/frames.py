"""Frames: Pinocchio frames by name, and the rotation maths, each written once.

URDF names links and joints separately: ANYmal C has a link and a joint both called
`LF_HFE`. Pinocchio keeps both as frames (BODY and JOINT), so a lookup by name alone
(`getFrameId(name)`, `existFrame(name)`) raises "Several frames match the filter", and
so does `buildReducedModel`, which looks frames up by name inside. Every lookup goes
through here: a name means the link first (`link_frame`), else the one frame of that name
(`frame_id`); `reduced_model` hides the clashes from Pinocchio while it reduces.

Rotations follow URDF: roll-pitch-yaw about fixed axes, R = Rz(yaw) Ry(pitch) Rx(roll).
Quaternions are (x, y, z, w), as ROS messages, tf2 and scipy order them; MuJoCo and the
viewer want (w, x, y, z) and reorder at their door. Everything here is plain numpy but
the frame lookups, which ask Pinocchio (imported inside them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.errors import InputError

Matrix = NDArray[np.float64]
Quat = tuple[float, float, float, float]  # (x, y, z, w)
_TAG = "#joint@armcli"  # a joint's temporary name while Pinocchio reduces the model


def link_frame(model: Any, name: str) -> int | None:
    """The Pinocchio frame id of the link `name`, None if there is no such link."""
    import pinocchio as pin

    if not model.existFrame(name, pin.BODY):
        return None
    return int(model.getFrameId(name, pin.BODY))


def joint_frame(model: Any, name: str) -> int | None:
    """The Pinocchio frame id of the joint `name` (its origin), None if there is no such joint."""
    import pinocchio as pin

    if not model.existFrame(name, pin.JOINT):
        return None
    return int(model.getFrameId(name, pin.JOINT))


def frame_id(model: Any, name: str, field: str | None = None) -> int:
    """The frame `name` names: the link's, else the only frame of that name (a joint's).

    InputError naming `field` and listing the links when no frame has that name.
    """
    found = link_frame(model, name)
    if found is not None:
        return found
    ids = [i for i, f in enumerate(model.frames) if f.name == name]
    if not ids:
        import pinocchio as pin

        links = ", ".join(sorted(str(f.name) for f in model.frames if f.type == pin.BODY))
        raise InputError(f"no link or frame named {name!r}; links: {links}", field=field)
    return ids[0]  # not a link: the joint's frame first, as Pinocchio orders them


def reduced_model(model: Any, lock: Sequence[int], q: Any) -> Any:
    """`pin.buildReducedModel(model, lock, q)` for a model whose links and joints share names.

    The clashing joints (and their frames) are renamed on a copy for the reduction and
    named back in the result, so the reduced model keeps the user's names.
    """
    import pinocchio as pin

    links = {f.name for f in model.frames if f.type == pin.BODY}
    clash = {str(n) for n in list(model.names)[1:] if n in links}
    if not clash:
        return pin.buildReducedModel(model, list(lock), q)
    work = pin.Model(model)
    for j in range(1, work.njoints):
        if work.names[j] in clash:
            work.names[j] = work.names[j] + _TAG
    for i, f in enumerate(work.frames):
        if f.name in clash and f.type != pin.BODY:
            work.frames[i].name = f.name + _TAG
    out = pin.buildReducedModel(work, list(lock), q)
    for j in range(1, out.njoints):
        if out.names[j].endswith(_TAG):
            out.names[j] = out.names[j][: -len(_TAG)]
    for i, f in enumerate(out.frames):
        if f.name.endswith(_TAG):
            out.frames[i].name = f.name[: -len(_TAG)]
    return out


def rpy_matrix(rpy: Sequence[float]) -> Matrix:
    """URDF fixed-axis roll-pitch-yaw: R = Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def rpy_rotation(rpy: Sequence[float] | NDArray[np.float64]) -> Matrix:
    """`rpy_matrix` as Pinocchio computes it (`pin.rpy.rpyToMatrix`), bit for bit.

    The orientation goal of `plan --to-rpy`: Eigen's angle-axis product, which the plans
    were made with (the closed form differs in the last bits, and so would the plans).
    """
    import pinocchio as pin

    return np.asarray(pin.rpy.rpyToMatrix(*(float(a) for a in rpy)), dtype=float)


def pose_matrix(xyz: Sequence[float], rpy: Sequence[float]) -> Matrix:
    """The 4x4 transform of a URDF origin (`xyz` [m], `rpy` [rad])."""
    T = np.eye(4)
    T[:3, :3] = rpy_matrix(rpy)
    T[:3, 3] = xyz
    return T


def rpy_quaternion(rpy: Sequence[float]) -> Quat:
    """(x, y, z, w) of URDF's fixed-axis roll-pitch-yaw, in closed form."""
    r, p, y = (0.5 * float(a) for a in rpy)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def yaw_quaternion(yaw: float) -> Quat:
    """(x, y, z, w) of a rotation by `yaw` [rad] about z (tf2's setRPY(0, 0, yaw))."""
    return 0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0)


def axis_quaternion(axis: ArrayLike, angle: float) -> NDArray[np.float64]:
    """(x, y, z, w) of a rotation by `angle` [rad] about the unit vector `axis`."""
    a = np.asarray(axis, dtype=float)
    s = math.sin(angle / 2.0)
    return np.array([a[0] * s, a[1] * s, a[2] * s, math.cos(angle / 2.0)])


def quaternion_product(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """Hamilton product a b of (x, y, z, w) quaternions: b's rotation first, then a's."""
    ax, ay, az, aw = np.asarray(a, dtype=float)
    bx, by, bz, bw = np.asarray(b, dtype=float)
    return np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )


def rotate(quat: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
    """The vector `v` turned by the unit (x, y, z, w) quaternion `quat`."""
    q = np.asarray(quat, dtype=float)
    u, w, v = q[:3], q[3], np.asarray(v, dtype=float)
    return np.asarray(v + 2.0 * np.cross(u, np.cross(u, v) + w * v), dtype=float)


def quaternion_matrix(quat: ArrayLike) -> Matrix:
    """The rotation matrix of a unit (x, y, z, w) quaternion."""
    x, y, z, w = np.asarray(quat, dtype=float)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def matrix_quaternion(R: ArrayLike) -> Quat:
    """(x, y, z, w) of a rotation matrix (Shepperd's method, w >= 0)."""
    R = np.asarray(R, dtype=float)
    w = 0.5 * np.sqrt(max(1.0 + R[0, 0] + R[1, 1] + R[2, 2], 0.0))
    if w > 1e-6:
        return (
            float((R[2, 1] - R[1, 2]) / (4 * w)),
            float((R[0, 2] - R[2, 0]) / (4 * w)),
            float((R[1, 0] - R[0, 1]) / (4 * w)),
            float(w),
        )
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    v = np.zeros(3)
    v[i] = 0.5 * np.sqrt(max(1.0 + R[i, i] - R[j, j] - R[k, k], 0.0))
    v[j] = (R[j, i] + R[i, j]) / (4 * v[i])
    v[k] = (R[k, i] + R[i, k]) / (4 * v[i])
    return float(v[0]), float(v[1]), float(v[2]), float((R[k, j] - R[j, k]) / (4 * v[i]))


def quaternion_rpy(wxyz: NDArray[Any]) -> tuple[NDArray[Any], NDArray[Any], NDArray[Any]]:
    """[rad] URDF's roll, pitch, yaw (R = Rz Ry Rx) of (w, x, y, z) rows; yaw unwrapped."""
    w, x, y, z = wxyz.T
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2.0 * (w * y - z * x), -1.0, 1.0))
    yaw = np.unwrap(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))
    return roll, pitch, yaw


def tilt(wxyz: NDArray[Any]) -> NDArray[np.float64]:
    """[rad] Angle between the frame's z axis and the vertical, from (w, x, y, z) rows."""
    x, y = wxyz[:, 1], wxyz[:, 2]
    z_z = 1.0 - 2.0 * (x * x + y * y) / np.maximum(np.sum(wxyz * wxyz, axis=1), 1e-300)
    return np.asarray(np.arccos(np.clip(z_z, -1.0, 1.0)), dtype=float)
