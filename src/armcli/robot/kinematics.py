"""A robot's kinematics and dynamics terms at a configuration: the methods `Robot` inherits.

Each method takes a Pinocchio configuration q (`Robot.q`) and works in the `Data` of the
calling thread (`Robot.data`). A frame is named by its link (a link wins over a joint of
the same name, `frames.frame_id`) or given by id. A point fixed in a frame is placed by
Pinocchio's own SE3 action, as every report of the tool point always was; a point's
Jacobian adds the lever arm to the frame's (the form `check`'s balance and reach use).
Pinocchio is imported inside the methods.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from armcli.errors import InputError
from armcli.robot.frames import frame_id, link_frame
from armcli.robot.tool import ToolPoint

Vector = NDArray[np.float64]


def _q(q: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(q, dtype=float)


class Kinematics:
    """Frames, points, Jacobians, mass matrix, gravity and centre of mass of `model`."""

    model: Any  # pinocchio.Model
    tool: ToolPoint | None
    source: str  # where the model came from: errors name it

    @property
    def data(self) -> Any:
        """The pinocchio.Data to compute in (`Robot.data`: one per thread)."""
        raise NotImplementedError

    def frame(self, name: str) -> int:
        """The Pinocchio frame id of the link `name`, else of the one frame so called.

        A link wins over a joint of the same name (`frames.frame_id`). InputError listing
        the links when there is no such frame.
        """
        return frame_id(self.model, name, field="link")

    @property
    def tool_frame(self) -> int:
        """The frame id of the tool point's link; InputError for a robot without one."""
        frame = link_frame(self.model, self.tool.link) if self.tool is not None else None
        if frame is None:
            raise InputError("this URDF has no link to use as the tool point", file=self.source)
        return frame

    def _fid(self, frame: str | int) -> int:
        return frame if isinstance(frame, int) else self.frame(frame)

    def frame_pose(self, frame: str | int, q: ArrayLike) -> NDArray[np.float64]:
        """T_root_frame: the 4x4 pose [m] at q of a link (or other frame), by name or id."""
        import pinocchio as pin

        fid = self._fid(frame)
        pin.forwardKinematics(self.model, self.data, _q(q))
        return np.asarray(pin.updateFramePlacement(self.model, self.data, fid).homogeneous)

    def point_position(self, frame: str | int, xyz: ArrayLike, q: ArrayLike) -> Vector:
        """A point fixed at `xyz` [m] in the link (or frame id) `frame`, in the root frame at q."""
        import pinocchio as pin

        fid = self._fid(frame)
        pin.forwardKinematics(self.model, self.data, _q(q))
        M = pin.updateFramePlacement(self.model, self.data, fid)
        return np.asarray(M.act(np.asarray(xyz, dtype=float)), dtype=float)

    def tool_position(self, q: ArrayLike) -> Vector:
        """The tool point (`tool`) in the root frame at q [m]."""
        frame = self.tool_frame  # InputError without a tool point
        return self.point_position(frame, self.tool.xyz if self.tool else (0.0, 0.0, 0.0), q)

    def jacobian(
        self,
        q: ArrayLike,
        link: str | None = None,
        xyz: ArrayLike = (0.0, 0.0, 0.0),
        columns: Sequence[int] | None = None,
    ) -> tuple[Vector, NDArray[np.float64]]:
        """(point [m], its (6, k) Jacobian) at q of a point fixed at `xyz` in `link`.

        Default point: the tool point. Rows 0-2: the point's velocity, rows 3-5: the link's
        angular velocity, in the root frame's axes, per joint velocity of `columns` (default:
        all nv). The point adds the lever arm r to the frame's (`frame_jacobian`):
        v_point = v_origin + ω × r = v_origin - [r]× ω.
        """
        p, r, J = self.frame_jacobian(q, link, xyz)
        if columns is not None:
            J = J[:, list(columns)]
        skew = np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
        return p, np.vstack([J[:3] - skew @ J[3:], J[3:]])

    def frame_jacobian(
        self, q: ArrayLike, link: str | None = None, xyz: ArrayLike = (0.0, 0.0, 0.0)
    ) -> tuple[Vector, Vector, NDArray[np.float64]]:
        """(point [m], lever arm r = R xyz [m], the link frame's (6, nv) Jacobian) at q.

        The point fixed at `xyz` in `link` (default: the tool point) and Pinocchio's
        LOCAL_WORLD_ALIGNED frame Jacobian of its link's origin, for a caller that composes
        the point's own (`jacobian`; plan's IK as v + ω × r). The link's pose is then in
        `data.oMf`.
        """
        import pinocchio as pin

        if link is None:
            fid = self.tool_frame  # InputError without a tool point
            xyz = self.tool.xyz if self.tool is not None else xyz
        else:
            fid = self.frame(link)
        J6 = pin.computeFrameJacobian(self.model, self.data, _q(q), fid, pin.LOCAL_WORLD_ALIGNED)
        J = np.asarray(J6, dtype=float).reshape(6, -1)  # nv = 1 comes back 1-D
        T = self.data.oMf[fid]
        r = np.asarray(T.rotation, dtype=float) @ np.asarray(xyz, dtype=float)
        return np.asarray(T.translation, dtype=float) + r, r, J

    def mass_matrix(self, q: ArrayLike) -> NDArray[np.float64]:
        """M(q) [kg·m² or kg], the whole symmetric matrix (CRBA fills only the upper triangle)."""
        import pinocchio as pin

        M = pin.crba(self.model, self.data, _q(q))
        return np.asarray(np.triu(M) + np.triu(M, 1).T, dtype=np.float64)

    def gravity(self, q: ArrayLike) -> Vector:
        """g(q) [N·m or N]: the joint torques that hold the robot still against gravity."""
        import pinocchio as pin

        return np.asarray(pin.computeGeneralizedGravity(self.model, self.data, _q(q)))

    def inverse_dynamics(self, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> Vector:
        """tau(q, v, a) [N·m or N]: the joint torques of that motion (RNEA), a fresh array."""
        import pinocchio as pin

        tau = pin.rnea(self.model, self.data, _q(q), _q(v), _q(a))
        return np.array(tau, dtype=float)

    def gravity_jacobian(self, q: ArrayLike) -> NDArray[np.float64]:
        """dg/dq [N·m/rad or N/m] as Pinocchio's derivatives give it (nv x nv), a fresh array."""
        import pinocchio as pin

        G = pin.computeGeneralizedGravityDerivatives(self.model, self.data, _q(q))
        return np.array(G, dtype=float)

    def gravity_stiffness(self, q: ArrayLike) -> NDArray[np.float64]:
        """dg/dq [N·m/rad or N/m], symmetrised: gravity's stiffness on the joints."""
        G = self.gravity_jacobian(q)
        return np.asarray(0.5 * (G + G.T), dtype=np.float64)

    def center_of_mass(self, q: ArrayLike) -> Vector:
        """The robot's centre of mass [m] in the root frame at q."""
        import pinocchio as pin

        return np.asarray(pin.centerOfMass(self.model, self.data, _q(q)), dtype=float)

    def center_of_mass_jacobian(self, q: ArrayLike) -> tuple[Vector, NDArray[np.float64]]:
        """(centre of mass [m], its (3, nv) Jacobian) in the root frame at q."""
        import pinocchio as pin

        J = np.array(pin.jacobianCenterOfMass(self.model, self.data, _q(q)))
        return np.array(self.data.com[0]), J.reshape(3, -1)  # nv = 1 comes back 1-D
