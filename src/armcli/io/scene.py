"""Planning-scene YAML shaped like moveit_msgs/PlanningScene's `world.collision_objects`.

One reader for the obstacles `plan --scene` plans around and the world `simulate --cmd-vel
--world` drives in (sim.world), so it sits below both.

A file holds `world: {collision_objects: [...]}` (a PlanningScene message) or the list
under a top-level `collision_objects`. Each object has an `id`, `header.frame_id` (a robot
link, or `world` / empty for the robot's root frame), an optional object `pose`, and
`primitives` (type `box` / `sphere` / `cylinder` / `cone` or SolidPrimitive's numbers 1-4,
with SolidPrimitive's `dimensions`) with one `primitive_poses` entry each, and/or `meshes`
(a `path` to a mesh file inside the scene file's directory, or a shape_msgs/Mesh's
`triangles` and `vertices`) with `mesh_poses`. Poses are geometry_msgs/Pose
(`position` x y z [m], `orientation` quaternion x y z w). Nothing outside the scene's
directory is read, and no file a mesh names (io.scenemesh).

A scene is bounded before it costs anything (issue 42: 40 objects naming one 19.9 MB PLY
reached 2.8 GB, ~8,700 small boxes did not finish in 90 s): at most MAX_SCENE_SHAPES
primitives and meshes and MAX_SCENE_TRIANGLES triangles in all (counted from what each
file declares before it is parsed), every coordinate and size within MAX_COORDINATE_M.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armcli.defaults import MAX_COORDINATE_M
from armcli.errors import InputError, Problem, SpecError
from armcli.io.packages import inside
from armcli.io.scenemesh import OverBudgetError, read_scene_mesh
from armcli.io.yaml import YamlDoc, dotted, is_finite_number, load_yaml

MAX_SCENE_SHAPES = 1000  # primitives and meshes: plan took 6 s with 1000 boxes, 77 s with 3000
MAX_SCENE_TRIANGLES = 500_000  # all meshes: ~0.85 kB each in plan's collision model (~0.4 GB)
WORLD_FRAMES = ("", "world")
PRIMITIVES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone"}  # SolidPrimitive constants
DIMENSIONS = {"box": 3, "sphere": 1, "cylinder": 2, "cone": 2}  # [x y z], [r], [h r], [h r]
_SCENE_KEYS = {
    "name",
    "world",
    "collision_objects",
    "robot_state",
    "robot_model_name",
    "is_diff",
    "fixed_frame_transforms",
    "allowed_collision_matrix",
    "link_padding",
    "link_scale",
    "object_colors",
}
_OBJECT_KEYS = {
    "id",
    "header",
    "pose",
    "primitives",
    "primitive_poses",
    "meshes",
    "mesh_poses",
    "operation",
    "type",
    "subframe_names",
    "subframe_poses",
    "planes",
    "plane_poses",
}
Path_ = tuple[str | int, ...]


@dataclass(frozen=True)
class Shape:
    """One solid of an object: `kind` box/sphere/cylinder/cone/mesh, in its object's frame."""

    kind: str
    dimensions: tuple[float, ...]  # SolidPrimitive's; () for a mesh
    T_frame_shape: np.ndarray  # 4x4 pose in the object's frame_id
    vertices: np.ndarray | None = None  # (V, 3) [m] for a mesh
    triangles: np.ndarray | None = None  # (F, 3) vertex indices


@dataclass(frozen=True)
class SceneObject:
    """A collision object: its id, the frame it is fixed to, and its shapes."""

    id: str
    frame: str  # a robot link, or "" for the root frame
    shapes: tuple[Shape, ...]


@dataclass(frozen=True)
class Scene:
    """The obstacles of a plan (empty: none)."""

    objects: tuple[SceneObject, ...] = ()
    source: str = ""


class _StopError(Exception):
    """A budget is spent: stop reading (the problem is recorded)."""


class _Reader:
    def __init__(self, doc: YamlDoc, links: Sequence[str]) -> None:
        self.doc = doc
        self.links = list(links)
        self.base = Path(doc.source).parent
        self.problems: list[Problem] = []
        self.shapes_read = 0
        self.triangles = 0  # read so far, against MAX_SCENE_TRIANGLES

    def add(self, path: Path_, message: str) -> None:
        self.problems.append(Problem(dotted(path), message, self.doc.line_of(path)))

    def stop(self, path: Path_, message: str) -> _StopError:
        self.add(path, message)
        return _StopError()

    def count(self, path: Path_) -> None:
        """One more shape against the scene's budget; stop past it."""
        self.shapes_read += 1
        if self.shapes_read > MAX_SCENE_SHAPES:
            raise self.stop(
                path,
                f"the scene holds more than {MAX_SCENE_SHAPES} primitives and "
                "meshes, armcli's bound on a scene",
            )

    def spend(self, path: Path_, triangles: int) -> None:
        """A mesh's triangles against the scene's budget; stop past it."""
        self.triangles += triangles
        if self.triangles > MAX_SCENE_TRIANGLES:
            raise self.stop(
                path,
                f"the scene's meshes hold more than {MAX_SCENE_TRIANGLES} "
                "triangles, armcli's bound on a scene",
            )

    def bounded(self, values: np.ndarray, path: Path_, what: str) -> bool:
        """Whether every value is finite and within ±MAX_COORDINATE_M; a problem if not."""
        with np.errstate(over="ignore", invalid="ignore"):
            ok = bool(np.all(np.abs(values) <= MAX_COORDINATE_M))
        if not ok:
            self.add(path, f"{what} must stay within ±{MAX_COORDINATE_M:g} m")
        return ok

    def keys(self, data: Mapping[str, Any], allowed: set[str], path: Path_) -> None:
        for key in data:
            if key not in allowed:
                self.add((*path, key), f"unknown key; expected one of {', '.join(sorted(allowed))}")

    def number(self, raw: Any, path: Path_, default: float | None = None) -> float:
        if raw is None and default is not None:
            return default
        if not is_finite_number(raw):
            self.add(path, f"must be a finite number, got {raw!r}")
            return 0.0
        return float(raw)

    def pose(self, raw: Any, path: Path_) -> np.ndarray:
        """geometry_msgs/Pose -> 4x4; a missing pose is the identity."""
        T = np.eye(4)
        if raw is None:
            return T
        if not isinstance(raw, dict):
            self.add(path, "must be a mapping with position and orientation")
            return T
        self.keys(raw, {"position", "orientation"}, path)
        pos, ori = raw.get("position") or {}, raw.get("orientation") or {}
        if not isinstance(pos, dict) or not isinstance(ori, dict):
            self.add(path, "position and orientation must be mappings like {x: 0, y: 0, z: 0}")
            return T
        self.keys(pos, {"x", "y", "z"}, (*path, "position"))
        self.keys(ori, {"x", "y", "z", "w"}, (*path, "orientation"))
        T[:3, 3] = [self.number(pos.get(k), (*path, "position", k), 0.0) for k in "xyz"]
        self.bounded(T[:3, 3], (*path, "position"), "a position")
        q = [self.number(ori.get(k), (*path, "orientation", k), 0.0) for k in "xyzw"]
        if "w" not in ori and not any(k in ori for k in "xyz"):
            q[3] = 1.0
        norm = math.sqrt(sum(x * x for x in q))
        if norm < 1e-9:
            self.add((*path, "orientation"), "quaternion has zero length")
            return T
        x, y, z, w = (v / norm for v in q)
        T[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
        return T

    def primitive(self, raw: Any, path: Path_) -> tuple[str, tuple[float, ...]] | None:
        if not isinstance(raw, dict):
            self.add(path, "must be a mapping like {type: box, dimensions: [0.1, 0.2, 0.3]}")
            return None
        self.keys(raw, {"type", "dimensions"}, path)
        kind = raw.get("type")
        if isinstance(kind, int) and not isinstance(kind, bool):
            kind = PRIMITIVES.get(kind, kind)
        if kind not in DIMENSIONS:
            valid = ", ".join(f"{n} ({k})" for k, n in PRIMITIVES.items())
            self.add((*path, "type"), f"unknown primitive {kind!r}; valid: {valid}")
            return None
        dims = raw.get("dimensions")
        n = DIMENSIONS[kind]
        if not isinstance(dims, list) or len(dims) != n:
            self.add((*path, "dimensions"), f"a {kind} needs {n} dimension(s) (SolidPrimitive)")
            return None
        values = tuple(self.number(d, (*path, "dimensions", i)) for i, d in enumerate(dims))
        if any(v <= 0 for v in values):
            self.add((*path, "dimensions"), f"must all be > 0 [m], got {list(values)}")
        self.bounded(np.array(values), (*path, "dimensions"), "dimensions")
        return str(kind), values

    def mesh(self, raw: Any, path: Path_) -> tuple[np.ndarray, np.ndarray] | None:
        if not isinstance(raw, dict):
            self.add(path, "must be a mapping with `path`, or `triangles` and `vertices`")
            return None
        self.keys(raw, {"path", "scale", "triangles", "vertices"}, path)
        if "path" in raw:
            return self.mesh_file(raw, path)
        tris, verts = raw.get("triangles"), raw.get("vertices")
        if not isinstance(tris, list) or not isinstance(verts, list) or not tris or not verts:
            self.add(path, "needs `path`, or non-empty `triangles` and `vertices`")
            return None
        self.spend((*path, "triangles"), len(tris))  # before any array is built
        v = np.array(
            [
                [
                    self.number(
                        p.get(k) if isinstance(p, dict) else None, (*path, "vertices", i, k)
                    )
                    for k in "xyz"
                ]
                for i, p in enumerate(verts)
            ]
        )
        f = []
        for i, t in enumerate(tris):
            idx = t.get("vertex_indices") if isinstance(t, dict) else None
            if not (
                isinstance(idx, list)
                and len(idx) == 3
                and all(
                    isinstance(k, int) and not isinstance(k, bool) and 0 <= k < len(v) for k in idx
                )
            ):
                self.add((*path, "triangles", i), f"needs vertex_indices: 3 of 0..{len(v) - 1}")
                return None
            f.append(idx)
        if not self.bounded(v, (*path, "vertices"), "vertices"):
            return None
        return v, np.array(f, dtype=int)

    def mesh_file(
        self, raw: Mapping[str, Any], path: Path_
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """A mesh file inside the scene file's directory, loaded by trimesh."""
        name = raw.get("path")
        scale = raw.get("scale", [1.0, 1.0, 1.0])
        if not isinstance(name, str) or not name:
            self.add((*path, "path"), "must be a file name relative to the scene file")
            return None
        if not (isinstance(scale, list) and len(scale) == 3):
            self.add((*path, "scale"), "must be [sx, sy, sz]")
            return None
        s = np.array([self.number(x, (*path, "scale", i)) for i, x in enumerate(scale)])
        if not np.all(s != 0):
            self.add((*path, "scale"), f"must be three nonzero numbers, got {scale}")
            return None
        file = (self.base / name).resolve()
        if not inside(file, (self.base.resolve(),)) or not file.is_file():
            self.add((*path, "path"), f"{name!r} is not a file inside {self.base}")
            return None
        try:
            vertices, faces = read_scene_mesh(
                file, self.doc.source, MAX_SCENE_TRIANGLES - self.triangles
            )
        except OverBudgetError as exc:
            raise self.stop(
                (*path, "path"),
                f"{name!r} {exc} of the scene's {MAX_SCENE_TRIANGLES}-triangle bound",
            ) from None
        except InputError as exc:
            self.add((*path, "path"), f"{name!r}: {exc.message}")
            return None
        if not len(faces):
            self.add((*path, "path"), f"{name!r} holds no triangles")
            return None
        self.spend((*path, "path"), len(faces))
        with np.errstate(over="ignore", invalid="ignore"):
            scaled = vertices * s  # 1e308 overflows to inf: refused below, never a warning
        if not self.bounded(scaled, (*path, "scale"), "the scaled vertices"):
            return None
        return scaled, faces

    def shapes(self, obj: Mapping[str, Any], path: Path_) -> list[Shape]:
        out = []
        T_obj = self.pose(obj.get("pose"), (*path, "pose"))
        for key, pose_key in (("primitives", "primitive_poses"), ("meshes", "mesh_poses")):
            items, poses = obj.get(key) or [], obj.get(pose_key) or []
            if not isinstance(items, list) or not isinstance(poses, list):
                self.add((*path, key), f"{key} and {pose_key} must be lists")
                continue
            if len(poses) != len(items):
                self.add((*path, pose_key), f"needs one pose per entry of {key} ({len(items)})")
                continue
            for i, (item, raw_pose) in enumerate(zip(items, poses, strict=True)):
                self.count((*path, key, i))
                T = T_obj @ self.pose(raw_pose, (*path, pose_key, i))
                if key == "primitives":
                    prim = self.primitive(item, (*path, key, i))
                    if prim is not None:
                        out.append(Shape(prim[0], prim[1], T))
                else:
                    mesh = self.mesh(item, (*path, key, i))
                    if mesh is not None:
                        out.append(Shape("mesh", (), T, mesh[0], mesh[1]))
        return out

    def obj(self, raw: Any, path: Path_, seen: set[str]) -> SceneObject | None:
        if not isinstance(raw, dict):
            self.add(path, "a collision object must be a mapping with id, header, primitives")
            return None
        self.keys(raw, _OBJECT_KEYS, path)
        oid = raw.get("id")
        if not isinstance(oid, str) or not oid:
            self.add((*path, "id"), "needs a non-empty string id")
            return None
        if oid in seen:
            self.add((*path, "id"), f"id {oid!r} used twice")
        seen.add(oid)
        header = raw.get("header") or {}
        frame = header.get("frame_id", "") if isinstance(header, dict) else None
        if not isinstance(frame, str):
            self.add((*path, "header"), "must be a mapping like {frame_id: world}")
            frame = ""
        if frame not in WORLD_FRAMES and frame not in self.links:
            valid = ", ".join(["world", *self.links])
            self.add((*path, "header", "frame_id"), f"unknown frame {frame!r}; valid: {valid}")
        shapes = self.shapes(raw, path)
        if not shapes and not any(p.field.startswith(dotted(path)) for p in self.problems):
            self.add(path, "has no primitives or meshes")
        frame = "" if frame in WORLD_FRAMES else frame
        return SceneObject(oid, frame, tuple(shapes))


def load_scene(path: str | Path, links: Sequence[str]) -> Scene:
    """Read and validate a scene file; `links` are the robot's link names (valid frames)."""
    return parse_scene(load_yaml(path), links)


def parse_scene(doc: YamlDoc, links: Sequence[str]) -> Scene:
    """Validate parsed YAML into a Scene, reporting every problem with file, line and field."""
    r = _Reader(doc, links)
    data = doc.data
    if not isinstance(data, dict):
        raise SpecError(doc.source, [Problem("", "a scene must be a YAML mapping", 1)])
    r.keys(data, _SCENE_KEYS, ())
    prefix: Path_ = ("collision_objects",)
    raw = data.get("collision_objects")
    world = data.get("world")
    if raw is None and isinstance(world, dict):
        r.keys(world, {"collision_objects", "octomap"}, ("world",))
        prefix, raw = ("world", "collision_objects"), world.get("collision_objects")
    if raw is None:
        raw = []
    if not isinstance(raw, list):
        r.add(prefix, "must be a list of collision objects")
        raw = []
    seen: set[str] = set()
    objects: list[SceneObject | None] = []
    try:
        if len(raw) > MAX_SCENE_SHAPES:  # each object holds a shape at least
            raise r.stop(
                prefix,
                f"{len(raw)} collision objects, more than the {MAX_SCENE_SHAPES}"
                " primitives and meshes armcli reads in a scene",
            )
        objects = [r.obj(o, (*prefix, i), seen) for i, o in enumerate(raw)]
    except _StopError:
        pass  # the problem is recorded
    if r.problems:
        raise SpecError(doc.source, r.problems)
    return Scene(tuple(o for o in objects if o is not None), doc.source)


def require_file(path: Path) -> None:
    """A clear error for a scene path that is not a file."""
    if not path.is_file():
        raise InputError("no such scene file", file=path)
