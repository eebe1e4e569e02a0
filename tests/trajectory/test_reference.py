"""The reference built for every segment at once equals the one-segment closed form, bitwise."""

from __future__ import annotations

import numpy as np

from armcli.trajectory.message import Trajectory
from armcli.trajectory.reference import build_reference, segment_coeffs


def one_by_one(traj: Trajectory) -> np.ndarray:
    """segment_coeffs (joint_trajectory_controller's closed forms) called per segment."""
    P, V, A, t = traj.positions, traj.velocities, traj.accelerations, traj.times
    return np.array([
        segment_coeffs(t[k + 1] - t[k], P[k], P[k + 1],
                       None if V is None else V[k], None if V is None else V[k + 1],
                       None if A is None else A[k], None if A is None else A[k + 1])
        for k in range(len(t) - 1)
    ]).reshape(-1, 6, P.shape[1])  # fmt: skip


def test_all_segments_at_once_are_bitwise_the_closed_form() -> None:
    rng = np.random.default_rng(0)
    for trial in range(60):
        points, n = int(rng.integers(1, 30)), int(rng.integers(1, 8))
        t = np.cumsum(rng.uniform(1e-3, 2.0, points))
        t -= t[0] if trial % 2 else 0.0  # a first point at 0, or later
        pos = rng.normal(size=(points, n))
        for order in range(3):  # linear, cubic, quintic
            vel = rng.normal(size=(points, n)) if order >= 1 else None
            acc = rng.normal(size=(points, n)) if order >= 2 else None
            names = tuple(f"j{i}" for i in range(n))
            traj = Trajectory(joint_names=names, times=t, positions=pos, velocities=vel,
                              accelerations=acc)  # fmt: skip
            ref = build_reference(traj, names, pos[0])
            rest = ref.coeffs[1:] if t[0] > 0.0 else ref.coeffs
            assert np.array_equal(rest, one_by_one(traj))  # the same floats, not just close
