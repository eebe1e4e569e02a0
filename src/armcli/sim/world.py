"""A scene file's objects in the MuJoCo world: static bodies with contact that sensors see.

`simulate --cmd-vel --world FILE` reads the same moveit_msgs/PlanningScene-shaped YAML as
`plan --scene` (io.scene: one reader) and `add_scene` puts each object into the model
editor (MjSpec) before it compiles. The scene's frame is the world: the floor at z = 0,
the robot's root (odom) at the origin at the start. An object whose `frame_id` is a robot
link rides on that link's body and collides with the world's objects only (as an object
attached in MoveIt), never with the robot that carries it.

Boxes, spheres and cylinders are MuJoCo primitives (SolidPrimitive's cylinder is
[height, radius], MuJoCo's [radius, half height]); a cone, which MuJoCo lacks, and a mesh
are meshes. MuJoCo collides a mesh by its convex hull, while rays (the sensors) hit its
triangles; a flat mesh (a sheet, which has no hull) gets a back face 1 mm behind it.
Every geom has sliding friction 0, as the drive's floor: MuJoCo combines two geoms by the
larger coefficient, so the robot geom's own (its Gazebo mu1) counts.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import InputError
from armcli.io.scene import Scene, SceneObject, Shape, load_scene, require_file

GROUP = 1  # geom group of the world's objects (floor 0, export: visual 2, collision 3)
PREFIX = "scene/"  # body, geom and mesh names of the objects: apart from the robot's
RGBA = (0.62, 0.6, 0.55, 1.0)  # a neutral grey for the camera
CONE_SEGMENTS = 64  # sides of the mesh standing in for a cone
# contact bits: the world's objects and the floor meet the robot (1) and what it carries (2)
WORLD_BITS, ROBOT_BITS, CARRIED_BITS = 3, 1, 2
MESH_VERTICES = 4  # MuJoCo refuses a mesh with fewer
FLAT_TOL = 1e-9  # relative thickness below which a mesh is flat
FLAT_BACK = 1e-3  # [m] how far behind a flat mesh its back face is put
OVERLAP_TOL = 1e-3  # [m] deeper than this at the start, an object and the robot overlap


@dataclass(frozen=True)
class WorldGeom:
    """One geom `add_scene` made: its name and the scene object (and shape) it stands for."""

    name: str
    object_id: str
    shape: int  # index of the shape in the object
    frame: str  # the robot link carrying it; "" for the world


def load_world(path: Path, links: Sequence[str]) -> Scene:
    """The scene file `path` (io.scene), objects on `links` allowed; InputError if missing."""
    require_file(path)
    return load_scene(path, links)


def add_scene(ms: Any, scene: Scene) -> tuple[WorldGeom, ...]:
    """Add the scene's objects to the MjSpec `ms` (before it compiles); returns their geoms.

    World objects become bodies without joints under the worldbody; an object on a robot
    link becomes geoms of that link's body (the export names bodies after links).
    """
    out = []
    for obj in scene.objects:
        if obj.frame:
            body, bits = _link_body(ms, obj, scene.source), (CARRIED_BITS, 0)
        else:
            body, bits = ms.worldbody.add_body(name=f"{PREFIX}{obj.id}"), (1, WORLD_BITS)
        for i, shape in enumerate(obj.shapes):
            name = f"{PREFIX}{obj.id}/{i}"
            geom = body.add_geom(name=name, group=GROUP, rgba=list(RGBA), friction=[0.0] * 3)
            geom.contype, geom.conaffinity = bits
            _shape(ms, geom, shape, name, scene.source)
            out.append(WorldGeom(name, obj.id, i, obj.frame))
    return tuple(out)


def _link_body(ms: Any, obj: SceneObject, source: str) -> Any:
    body = ms.body(obj.frame)
    if body is None:  # io.scene checked the frame against the links the model has
        raise InputError(f"object {obj.id!r}: no body {obj.frame!r}", file=source)
    return body


def _shape(ms: Any, geom: Any, shape: Shape, name: str, source: str) -> None:
    """Type, size and pose of `geom` for `shape` (a mesh asset for a cone or a mesh)."""
    import mujoco

    G = mujoco.mjtGeom
    d = shape.dimensions
    geom.pos = shape.T_frame_shape[:3, 3]
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(shape.T_frame_shape[:3, :3]).ravel())
    geom.quat = quat
    if shape.kind == "box":
        geom.type, geom.size = G.mjGEOM_BOX, [d[0] / 2, d[1] / 2, d[2] / 2]
    elif shape.kind == "sphere":
        geom.type, geom.size = G.mjGEOM_SPHERE, [d[0], 0.0, 0.0]
    elif shape.kind == "cylinder":
        geom.type, geom.size = G.mjGEOM_CYLINDER, [d[1], d[0] / 2, 0.0]
    else:
        vertices, faces = _cone(d) if shape.kind == "cone" else _mesh(shape)
        if len(vertices) < MESH_VERTICES:
            oid = name[len(PREFIX) :].rsplit("/", 1)[0]
            raise InputError(
                f"object {oid!r}: a mesh needs at least {MESH_VERTICES} vertices "
                "(MuJoCo's convex hull)",
                file=source,
            )
        mesh = ms.add_mesh(name=name, uservert=vertices.ravel(), userface=faces.ravel())
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL  # a static body: no volume needed
        geom.type, geom.meshname = G.mjGEOM_MESH, name


def _mesh(shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """The mesh; a flat one (no convex hull, which MuJoCo needs) backed by a FLAT_BACK copy."""
    assert shape.vertices is not None and shape.triangles is not None  # io.scene's meshes
    v = np.asarray(shape.vertices, dtype=float)
    f = np.asarray(shape.triangles, dtype=np.int32)
    if len(v) < MESH_VERTICES:
        return v, f
    _, sv, vt = np.linalg.svd(v - v.mean(axis=0))
    if sv[2] > FLAT_TOL * max(sv[0], 1e-12):
        return v, f
    normal = vt[2] if np.dot(np.cross(*(v[f[0, 1:]] - v[f[0, 0]])), vt[2]) > 0 else -vt[2]
    back = v - FLAT_BACK * normal  # behind the first triangle's front (its winding)
    return np.vstack([v, back]), np.vstack([f, f[:, ::-1] + len(v)])


def _cone(d: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """SolidPrimitive's cone [height, radius], centred on its axis' midpoint, as a mesh."""
    height, radius = d
    # half a segment turned: no edge in the planes x = 0 or y = 0, which axis-aligned rays
    # (a lidar's first ray at the start) would graze, MuJoCo's ray-triangle test not being
    # watertight on an edge
    a = np.linspace(0.0, 2 * np.pi, CONE_SEGMENTS, endpoint=False) + np.pi / CONE_SEGMENTS
    rim = np.column_stack([radius * np.cos(a), radius * np.sin(a), np.full_like(a, -height / 2)])
    vertices = np.vstack([rim, [[0.0, 0.0, height / 2], [0.0, 0.0, -height / 2]]])
    n, apex, centre = CONE_SEGMENTS, CONE_SEGMENTS, CONE_SEGMENTS + 1
    faces = [(i, (i + 1) % n, apex) for i in range(n)]
    faces += [((i + 1) % n, i, centre) for i in range(n)]
    return vertices, np.array(faces, dtype=np.int32)


def geom_ids(model: Any, geoms: Sequence[WorldGeom]) -> np.ndarray:
    """The compiled model's ids of `geoms`."""
    return np.array([model.geom(g.name).id for g in geoms], dtype=np.int32)


def overlaps(model: Any, data: Any, geoms: Sequence[WorldGeom]) -> Iterator[tuple[str, str, float]]:
    """(object id, robot body, depth [m]) of world objects the robot penetrates in `data`.

    `data` must have been through mj_forward (its contacts found).
    """
    ids = {int(i): g for i, g in zip(geom_ids(model, geoms), geoms, strict=True)}
    for c in data.contact[: data.ncon]:
        pair = (int(c.geom[0]), int(c.geom[1]))
        for mine, other in (pair, pair[::-1]):
            g = ids.get(mine)
            if g is not None and not g.frame and other not in ids and c.dist < -OVERLAP_TOL:
                body = model.body(int(model.geom_bodyid[other])).name
                if body != "world":  # the floor
                    yield g.object_id, body, -float(c.dist)


def refuse_overlaps(model: Any, data: Any, geoms: Sequence[WorldGeom], source: str) -> None:
    """InputError naming the first world object the robot stands in at the start."""
    for oid, body, depth in overlaps(model, data, geoms):
        raise InputError(
            f"object {oid!r} overlaps the robot's {body} by {depth * 1e3:.0f} mm at the start "
            "(the world's frame is odom at the start: the robot's root at the origin)",
            file=source,
        )


# -- the world as visualization_msgs/MarkerArray (the MCAP's /world) ---------------------------

MARKERS = {
    "box": 1,
    "sphere": 2,
    "cylinder": 3,
    "mesh": 11,
}  # CUBE, SPHERE, CYLINDER, TRIANGLE_LIST


def marker_array(model: Any, data: Any, geoms: Sequence[WorldGeom]) -> dict[str, Any]:
    """The world's objects as a MarkerArray message: in `world`, or on their link.

    Each geom's pose is MuJoCo's (a mesh in its own frame, which MuJoCo may have moved to
    the mesh's centre), so Foxglove and RViz draw exactly what the sensors see.
    """
    import mujoco

    out = []
    for i, g in enumerate(geoms):
        gid = model.geom(g.name).id
        kind = mujoco.mjtGeom(model.geom_type[gid]).name[len("mjGEOM_") :].lower()
        if g.frame:  # on a link: its pose in the link's body, the marker follows the link
            pos, quat = model.geom_pos[gid], model.geom_quat[gid]
        else:
            pos, quat = data.geom_xpos[gid], np.zeros(4)
            mujoco.mju_mat2Quat(quat, data.geom_xmat[gid])
        size = model.geom_size[gid]
        d = 2 * size
        scale = {"box": d, "sphere": [d[0]] * 3, "cylinder": [d[0], d[0], d[1]]}.get(kind, [1] * 3)
        r, gr, b, a = (float(c) for c in model.geom_rgba[gid])
        marker = {
            "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": g.frame or "world"},
            "ns": g.object_id,
            "id": i,
            "type": MARKERS.get(kind, 11),
            "action": 0,
            "pose": {
                "position": dict(zip("xyz", map(float, pos), strict=True)),
                "orientation": dict(zip("wxyz", map(float, quat), strict=True)),
            },
            "scale": dict(zip("xyz", map(float, scale), strict=True)),
            "color": {"r": r, "g": gr, "b": b, "a": a},
            "frame_locked": bool(g.frame),
            "points": _triangles(model, gid) if kind == "mesh" else [],
        }
        out.append(marker)
    return {"markers": out}


def _triangles(model: Any, gid: int) -> list[dict[str, float]]:
    """A mesh geom's triangles as a TRIANGLE_LIST's points, in the geom's frame."""
    mesh = int(model.geom_dataid[gid])
    v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    f0, nf = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    verts = model.mesh_vert[v0 : v0 + nv]
    corners = verts[model.mesh_face[f0 : f0 + nf].reshape(-1)]
    return [{"x": float(x), "y": float(y), "z": float(z)} for x, y, z in corners]
