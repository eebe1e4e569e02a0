"""Mesh files for the MJCF model: bounded like `check`'s, in a form MuJoCo decodes.

Each mesh is read once, under the caps `check` and `render` apply (urdf.mesh_confine:
a regular file, symlinks resolved, per-file and per-robot byte limits), so a hostile
URDF cannot make the export read or write gigabytes. Then what MuJoCo's decoders
need: its STL reader takes binary STL only, of at most MJ_STL_MAX_FACES faces, so an
ASCII STL is rewritten as binary and a larger one is left out (with a note). MuJoCo
computes every mesh's inertia even where nothing uses it, and its default ("legacy",
from the faces) refuses the misoriented or open meshes common in robot packages
("mesh volume is too small"), so meshes use the convex hull's (`inertia="convex"`,
the shape MuJoCo collides with), and a flat mesh, whose hull has no volume, its
surface's (`inertia="shell"`, as MuJoCo's error message advises); a flat mesh cannot
collide in MuJoCo (no convex hull), so it is drawn but gets no collision geom.
MuJoCo reads no COLLADA (.dae), which ROS descriptions use for visuals and often for
collisions too (Doosan's M1013: every collision mesh); trimesh reads it, and the export
writes it as binary STL, in metres (COLLADA's <unit meter> applied, as ROS's loaders do).
"""

from __future__ import annotations

import io
import re
import struct
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np
from lxml import etree

from armcli.compiler.xmlfmt import vec
from armcli.export.mjcf_report import Note
from armcli.io.mesh_confine import MAX_MESH_BYTES, bounded_mesh_file, check_total
from armcli.io.userfile import read_regular
from armcli.urdf.doc import Urdf
from armcli.urdf.meshlog import quiet_trimesh

MESH_SUFFIXES = (".stl", ".obj", ".msh")  # what MuJoCo loads
CONVERTED_SUFFIXES = (".dae",)  # what the export converts to binary STL (through trimesh)
MESH_DIR = "meshes"
MJ_STL_MAX_FACES = 200_000  # MuJoCo's STL decoder refuses files with more faces
FLAT_RTOL = 1e-9  # thickness / size below which a mesh is flat (no volume for MuJoCo)
_STL_HEADER = b"binary STL written by armcli export mjcf from an ASCII STL".ljust(80)
_STL_HEADER_DAE = b"binary STL written by armcli export mjcf from a COLLADA file".ljust(80)
_FLOAT = rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_ASCII_VERTEX = re.compile(
    rb"vertex\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")"
)
_OBJ_VERTEX = re.compile(
    rb"^v\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")\s+(" + _FLOAT + rb")", re.M
)
_OBJ_FACE = re.compile(rb"^f\s", re.M)


@dataclass(frozen=True)
class MeshFile:
    """A mesh as the export writes it, or why it is left out."""

    data: bytes
    suffix: str  # ".stl" | ".obj" | ".msh"
    faces: int | None  # None where armcli does not parse the format (.msh)
    flat: bool  # all vertices in one plane: MuJoCo needs inertia="shell"
    converted: bool  # an ASCII STL (or a COLLADA file) rewritten as binary STL
    skip: str | None = None  # why MuJoCo cannot use it


def real_paths(paths: Iterable[Path], source: str) -> dict[Path, Path]:
    """Each path's bounded real file; refuses the robot when they add up past the cap."""
    real = {p: bounded_mesh_file(p, source) for p in paths}
    check_total(real.values(), source)
    return real


def read_mesh(real: Path) -> MeshFile:
    """The mesh at the (bounded, real) path, prepared for MuJoCo."""
    data = read_regular(real, max_bytes=MAX_MESH_BYTES, what="mesh file")
    suffix = real.suffix.lower()
    if suffix == ".dae":
        return _collada(data)
    if suffix == ".stl":
        return _stl(data)
    if suffix == ".obj":
        v = np.array(_OBJ_VERTEX.findall(data), dtype=float).reshape(-1, 3)
        return MeshFile(data, suffix, len(_OBJ_FACE.findall(data)), is_flat(v), False)
    return MeshFile(data, suffix, None, False, False)


def _stl(data: bytes) -> MeshFile:
    if len(data) >= 84:
        (n,) = struct.unpack_from("<I", data, 80)
        if len(data) == 84 + 50 * n:  # binary: 80-byte header, count, 50 bytes per face
            rec = np.frombuffer(data, dtype=_FACET, count=n, offset=84)
            return _checked(data, n, rec["v"].reshape(-1, 3), False)
    v = np.array(_ASCII_VERTEX.findall(data), dtype=float).reshape(-1, 3)
    if not data.lstrip().startswith(b"solid") or not len(v) or len(v) % 3:
        return MeshFile(data, ".stl", None, False, False, "neither binary nor ASCII STL")
    n = len(v) // 3
    rec = np.zeros(n, dtype=_FACET)
    rec["v"] = v.reshape(n, 3, 3)
    binary = _STL_HEADER + struct.pack("<I", n) + rec.tobytes()
    return _checked(binary, n, v, True)


def _collada(data: bytes) -> MeshFile:
    """A COLLADA file as binary STL: every triangle of its scene, placed, in metres."""
    import trimesh

    try:
        with quiet_trimesh():  # a missing texture does not change a triangle
            mesh: Any = trimesh.load(io.BytesIO(data), file_type="dae", force="mesh", process=False)
        v = np.asarray(mesh.vertices, dtype=np.float64) * _collada_unit(data)
        f = np.asarray(mesh.faces, dtype=np.int64)
    except Exception as exc:  # trimesh and pycollada raise many types for bad files
        return MeshFile(data, ".dae", None, False, False, f"COLLADA not readable: {exc}")
    if v.ndim != 2 or f.ndim != 2 or not len(f):
        return MeshFile(data, ".dae", None, False, False, "COLLADA file without triangles")
    rec = np.zeros(len(f), dtype=_FACET)
    rec["v"] = v[f]
    binary = _STL_HEADER_DAE + struct.pack("<I", len(f)) + rec.tobytes()
    return _checked(binary, len(f), v, True)


def _collada_unit(data: bytes) -> float:
    """COLLADA's <asset><unit meter="..."> (1 when absent or unusable)."""
    try:
        root = etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError:
        return 1.0
    unit = root.find("{*}asset/{*}unit")
    try:
        meter = float(unit.get("meter", "1")) if unit is not None else 1.0
    except ValueError:
        return 1.0
    return meter if np.isfinite(meter) and meter > 0 else 1.0


_FACET = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])


def _checked(data: bytes, faces: int, vertices: np.ndarray, converted: bool) -> MeshFile:
    skip = None
    if not 1 <= faces <= MJ_STL_MAX_FACES:
        skip = f"{faces} faces; MuJoCo's STL reader takes 1 to {MJ_STL_MAX_FACES}"
    return MeshFile(data, ".stl", faces, is_flat(vertices), converted, skip)


def is_flat(vertices: np.ndarray) -> bool:
    """Whether the points lie in one plane (or line), so their hull has no volume."""
    v = np.asarray(vertices, dtype=float)
    if len(v) < 4:
        return True
    s = np.linalg.svd(v - v.mean(axis=0), compute_uv=False)
    return bool(s[-1] <= FLAT_RTOL * s[0])


@dataclass(frozen=True)
class Assets:
    """The `<asset>` element, URI -> asset name, files to write, and the notes."""

    element: etree._Element
    names: dict[str, str]  # mesh URI -> asset name
    files: dict[str, bytes]  # meshes/NAME.ext -> content
    notes: list[Note]
    flat: frozenset[str]  # URIs of flat meshes: no collision geom (MuJoCo needs a hull)


def mesh_assets(urdf: Urdf, meshes: Mapping[str, Path | None]) -> Assets:
    """One `<mesh>` per usable URI, its file under meshes/, and what was left out or changed."""
    asset = etree.Element("asset")
    scales = {
        s.geometry.filename: s.geometry.scale
        for lk in urdf.links
        for s in (*lk.visuals, *lk.collisions)
        if s.geometry is not None and s.geometry.filename
    }
    ok = {u: p for u, p in meshes.items() if p is not None and p.is_file()}
    usable = (*MESH_SUFFIXES, *CONVERTED_SUFFIXES)
    ok = {u: p for u, p in ok.items() if p.suffix.lower() in usable}
    real = real_paths(ok.values(), urdf.source)  # bounded before any is read
    read: dict[Path, MeshFile] = {}
    names: dict[str, str] = {}
    files: dict[str, bytes] = {}
    log: dict[str, list[str]] = {}
    for uri in sorted(meshes):
        if uri not in ok:
            log.setdefault("missing or not STL/OBJ/MSH", []).append(uri)
            continue
        path = real[ok[uri]]
        mf = read[path] = read.get(path) or read_mesh(path)
        if mf.skip is not None:
            log.setdefault("not decodable by MuJoCo", []).append(f"{uri} ({mf.skip})")
            continue
        stem = _unique(ok[uri].stem, set(names.values()))
        names[uri] = stem
        rel = str(PurePosixPath(MESH_DIR) / f"{stem}{mf.suffix}")
        files[rel] = mf.data
        attrs = {"name": stem, "file": rel}
        if scales.get(uri, (1.0, 1.0, 1.0)) != (1.0, 1.0, 1.0):
            attrs["scale"] = vec(scales[uri])
        attrs["inertia"] = "shell" if mf.flat else "convex"
        if mf.flat:
            log.setdefault("flat", []).append(uri)
        if mf.converted:
            kind = "COLLADA" if ok[uri].suffix.lower() == ".dae" else "ASCII STL"
            log.setdefault(kind, []).append(uri)
        etree.SubElement(asset, "mesh", attrs)
    notes = [Note("meshes", ", ".join(v), _DONE[k]) for k, v in log.items()]
    return Assets(asset, names, files, notes, frozenset(log.get("flat", ())))


_DONE = {
    "missing or not STL/OBJ/MSH": "left out of the model (missing, or convert them to STL or OBJ)",
    "COLLADA": "converted to binary STL in metres (MuJoCo reads no COLLADA)",
    "not decodable by MuJoCo": "left out of the model (MuJoCo cannot decode them)",
    "flat": 'all vertices in one plane: display only, with inertia="shell" (MuJoCo needs a '
    "volume for the mesh's inertia and a convex hull for contact)",
    "ASCII STL": "rewritten as binary STL (MuJoCo reads binary STL only)",
}


def _unique(stem: str, taken: set[str]) -> str:
    name, k = stem, 1
    while name in taken:
        k += 1
        name = f"{stem}_{k}"
    return name
