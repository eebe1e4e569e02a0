"""Test meshes written by hand (binary STL) and their mass properties by the divergence theorem.

Independent of trimesh: the triangles are listed here, and `mass_properties` sums the
signed tetrahedra (origin, a, b, c) of a closed, outward-wound surface, the textbook
route to volume, centre of mass and second moments of a polyhedron.
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np

Triangle = tuple[np.ndarray, np.ndarray, np.ndarray]


def write_stl(path: Path, triangles: list[Triangle]) -> Path:
    """A binary STL of `triangles` (normals left zero; readers recompute them)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    out = bytearray(b"armcli test mesh".ljust(80, b" "))
    out += struct.pack("<I", len(triangles))
    for tri in triangles:
        out += struct.pack("<3f", 0.0, 0.0, 0.0)
        for v in tri:
            out += struct.pack("<3f", *(float(x) for x in v))
        out += b"\0\0"
    path.write_bytes(bytes(out))
    return path


def _quad(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> list[Triangle]:
    return [(a, b, c), (a, c, d)]


def box_triangles(size: tuple[float, float, float], centre=(0.0, 0.0, 0.0)) -> list[Triangle]:
    """An axis-aligned box, outward winding."""
    hx, hy, hz = (s / 2 for s in size)
    c = np.array(centre, dtype=float)
    v = {
        (i, j, k): c + np.array([i * hx, j * hy, k * hz])
        for i in (-1, 1)
        for j in (-1, 1)
        for k in (-1, 1)
    }
    faces = [
        ((1, -1, -1), (1, 1, -1), (1, 1, 1), (1, -1, 1)),  # +x
        ((-1, -1, -1), (-1, -1, 1), (-1, 1, 1), (-1, 1, -1)),  # -x
        ((-1, 1, -1), (-1, 1, 1), (1, 1, 1), (1, 1, -1)),  # +y
        ((-1, -1, -1), (1, -1, -1), (1, -1, 1), (-1, -1, 1)),  # -y
        ((-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)),  # +z
        ((-1, -1, -1), (-1, 1, -1), (1, 1, -1), (1, -1, -1)),  # -z
    ]
    out: list[Triangle] = []
    for f in faces:
        out += _quad(*(v[k] for k in f))
    return out


def prism_triangles(radius: float, length: float, n: int) -> list[Triangle]:
    """A regular n-gon prism along z, centred at the origin (a faceted cylinder)."""
    ring = [
        np.array([radius * math.cos(2 * math.pi * i / n), radius * math.sin(2 * math.pi * i / n)])
        for i in range(n)
    ]
    top, bottom = np.array([0, 0, length / 2]), np.array([0, 0, -length / 2])
    out: list[Triangle] = []
    for i in range(n):
        p, q = ring[i], ring[(i + 1) % n]
        p0, q0 = np.append(p, -length / 2), np.append(q, -length / 2)
        p1, q1 = np.append(p, length / 2), np.append(q, length / 2)
        out += _quad(p0, q0, q1, p1)
        out.append((top, p1, q1))
        out.append((bottom, q0, p0))
    return out


def house_triangles() -> list[Triangle]:
    """A unit-ish cube with a roof: no symmetry plane through its centroid along z."""
    tris = [t for t in box_triangles((0.2, 0.1, 0.1), (0.1, 0.05, 0.05)) if not _on_top(t)]
    apex = np.array([0.15, 0.05, 0.18])  # off-centre apex: products of inertia are non-zero
    corners = [
        np.array(c, dtype=float)
        for c in ((0, 0, 0.1), (0.2, 0, 0.1), (0.2, 0.1, 0.1), (0, 0.1, 0.1))
    ]
    for i in range(4):
        tris.append((corners[i], corners[(i + 1) % 4], apex))
    return tris


def _on_top(t: Triangle) -> bool:
    return all(abs(v[2] - 0.1) < 1e-12 for v in t)


def mass_properties(
    triangles: list[Triangle], density: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass [kg], centre of mass [m], inertia about it [kg·m²]) of the enclosed solid."""
    volume, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    for a, b, c in triangles:
        a, b, c = (np.asarray(x, dtype=float) for x in (a, b, c))
        det = float(np.dot(a, np.cross(b, c)))  # 6 x signed volume of (0, a, b, c)
        volume += det / 6.0
        first += det / 24.0 * (a + b + c)
        s = a + b + c
        second += det / 120.0 * (np.outer(a, a) + np.outer(b, b) + np.outer(c, c) + np.outer(s, s))
    com = first / volume
    J_origin = density * (np.trace(second) * np.eye(3) - second)
    mass = density * volume
    J_com = J_origin - mass * (np.dot(com, com) * np.eye(3) - np.outer(com, com))
    return mass, com, J_com


def as_stored(triangles: list[Triangle]) -> list[Triangle]:
    """The triangles as a binary STL stores them (float32 coordinates)."""
    return [
        (
            np.asarray(a, np.float32).astype(float),
            np.asarray(b, np.float32).astype(float),
            np.asarray(c, np.float32).astype(float),
        )
        for a, b, c in triangles
    ]
