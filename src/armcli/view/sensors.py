"""A replay's scans, point clouds and world objects in the browser viewer.

The world's objects (the MCAP's `/world` markers) are drawn once, in the world frame. At
each replay time every scan or cloud topic shows its latest message at or before that
time, in its frame: the robot's model at that instant (its joints as replayed) gives the
frame's pose in the robot's root, under the node that carries the robot through the
world, so a scan taken while driving sits where the lidar was. Clouds whose frame is
not a link of the robot are not drawn (a note says which).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from armcli.sim.sensors.replay import SensorReplay, WorldShape

SCAN_POINT, CLOUD_POINT = 0.03, 0.012  # [m] drawn sizes: a scan's few points, a cloud's many
SCAN_RGB, CLOUD_RGB = (255, 120, 0), (0, 170, 255)  # scans orange, point clouds blue


class SensorLayer:
    """The scene nodes of a replay's sensors: point clouds under `root`, the world at `/`."""

    def __init__(self, server: Any, urdf: Any, replay: SensorReplay, root: str) -> None:
        self.server, self.urdf, self.replay, self.root = server, urdf, replay, root
        links = set(urdf.link_map)
        self.tracks = [t for t in replay.tracks if t.frame in links]
        self.notes = tuple(
            f"{t.topic}: frame {t.frame!r} is not a link of the robot; not drawn"
            for t in replay.tracks
            if t.frame not in links
        )
        self.handles: dict[str, Any] = {}  # topic -> its point cloud node
        for i, shape in enumerate(replay.world):
            _add_shape(server, f"/world/{i}", shape)
        if replay.world:  # look at the world from above and behind the start
            far = max(max(abs(v) for v in s.pose[:2]) for s in replay.world)
            server.initial_camera.position = (-0.6 * far, -0.9 * far, 1.2 * far)
            server.initial_camera.look_at = (0.4 * far, 0.0, 0.0)

    def show(self, t: float) -> None:
        """Each topic's latest cloud at time `t` [s], placed by the robot's current pose."""
        for track in self.tracks:
            i = track.at(t)
            name = f"{self.root}/sensors{track.topic}"
            if i is None:
                pts = np.zeros((0, 3))
            else:
                T = self.urdf.get_transform(track.frame, self.urdf.base_link)
                pts = track.points[i] @ T[:3, :3].T + T[:3, 3]
            scan = track.kind == "scan"
            self.handles[track.topic] = self.server.scene.add_point_cloud(
                name,
                pts.astype(np.float32),
                SCAN_RGB if scan else CLOUD_RGB,
                point_size=SCAN_POINT if scan else CLOUD_POINT,
                point_shape="circle",
                precision="float32",
            )


def _add_shape(server: Any, name: str, s: WorldShape) -> None:
    import trimesh

    if s.kind == "box":
        mesh = trimesh.creation.box(extents=s.scale)
    elif s.kind == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=3, radius=s.scale[0] / 2)
    elif s.kind == "cylinder":
        mesh = trimesh.creation.cylinder(radius=s.scale[0] / 2, height=s.scale[2])
    else:
        assert s.triangles is not None
        vertices = s.triangles.reshape(-1, 3)
        mesh = trimesh.Trimesh(vertices, np.arange(len(vertices)).reshape(-1, 3), process=False)
    rgb = tuple(round(255 * c) for c in s.rgba[:3])
    server.scene.add_mesh_simple(
        name,
        np.asarray(mesh.vertices),
        np.asarray(mesh.faces),
        color=rgb,
        opacity=s.rgba[3] if s.rgba[3] < 1 else None,
        position=s.pose[:3],
        wxyz=s.pose[3:],
        side="double",
    )
