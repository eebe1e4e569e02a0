"""One lidar scan seen from above, over the world's objects: a drive plot's last row.

The world's objects are drawn as their outlines seen from above (the convex hull of the
shape's corners or rim points, projected on the floor), the robot's path as the ground
truth of its root, and the scan that `simulate --plot` shows: the lidar's sample in the
middle of the run, each return a dot where the ray ended (the sensor's recorded pose
times the ray), coloured by range. Without a lidar the row shows the world and the path.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from armcli.sim.sensors.messages import scan_points
from armcli.sim.sensors.reading import Reading

RIM = 32  # points on a circle's outline


def pick_scan(readings: tuple[Reading, ...]) -> tuple[Reading, int] | None:
    """(the first lidar's reading, its sample in the middle of the run), or None."""
    for r in readings:
        if r.sensor.type == "lidar" and len(r.steps):
            return r, len(r.steps) // 2
    return None


def draw_scan(
    ax: Any,
    model: Any,
    data: Any,
    geoms: tuple[Any, ...],
    path: np.ndarray,
    readings: tuple[Reading, ...],
) -> None:
    """Draw the world (`geoms` in `data`), the `path` (n, 2) and one scan on `ax`."""
    for g in geoms:
        if not g.frame:
            hull = _outline(model, data, model.geom(g.name).id)
            ax.fill(hull[:, 0], hull[:, 1], color="0.55", alpha=0.6, lw=0)
    ax.plot(path[:, 0], path[:, 1], color="C0", lw=1.2, label="base path (truth)")
    picked = pick_scan(readings)
    title = "world seen from above"
    if picked is not None:
        r, j = picked
        pose = r.data["pose"][j]
        origin, R = pose[:3], pose[3:].reshape(3, 3)
        pts = scan_points(r, j) @ R.T + origin
        rng = np.linalg.norm(pts - origin, axis=1)
        dots = ax.scatter(pts[:, 0], pts[:, 1], c=rng, s=4, cmap="viridis", label="returns")
        ax.figure.colorbar(dots, ax=ax, pad=0.01, label="range [m]")
        ax.plot(*origin[:2], "^", color="C3", ms=7, label=f"{r.name} (lidar)")
        title = f"scan of {r.name} at t = {r.time[j]:.2f} s over the world, seen from above"
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=11)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(True, alpha=0.3)


def _outline(model: Any, data: Any, gid: int) -> np.ndarray:
    """The geom's outline on the floor: the convex hull of its corners or rims, projected."""
    size, kind = model.geom_size[gid], int(model.geom_type[gid])
    import mujoco

    G = mujoco.mjtGeom
    a = np.linspace(0, 2 * np.pi, RIM, endpoint=False)
    if kind == G.mjGEOM_BOX:
        local = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * size
    elif kind in (G.mjGEOM_CYLINDER, G.mjGEOM_SPHERE, G.mjGEOM_CAPSULE):
        r, h = size[0], size[1] if kind != G.mjGEOM_SPHERE else 0.0
        rim = np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros(RIM)])
        up = np.array([0.0, 0.0, h])
        local = np.vstack([rim + up, rim - up])
    else:  # a mesh: its vertices
        mesh = int(model.geom_dataid[gid])
        v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
        local = np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=float)
    world = local @ data.geom_xmat[gid].reshape(3, 3).T + data.geom_xpos[gid]
    return hull_2d(world[:, :2])


def hull_2d(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise, closed (Andrew's monotone chain)."""
    pts = sorted(map(tuple, np.round(points, 12)))
    if len(pts) < 3:
        return np.array(pts + pts[:1])

    def half(seq: list[tuple[float, ...]]) -> list[tuple[float, ...]]:
        out: list[tuple[float, ...]] = []
        for p in seq:
            while len(out) >= 2 and _cross(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    ring = lower[:-1] + upper[:-1]
    return np.array([*ring, ring[0]])


def _cross(o: tuple[float, ...], a: tuple[float, ...], b: tuple[float, ...]) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
