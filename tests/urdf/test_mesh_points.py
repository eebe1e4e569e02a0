"""Mesh vertices read with numpy for the ground contacts, against trimesh (a second reader)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from armcli.urdf.mesh_points import read_vertices

trimesh = pytest.importorskip("trimesh")

SEED = 3
EXACT = 1e-6  # [m] float32 STL coordinates of values near 1


@pytest.fixture
def mesh() -> object:
    """A seeded, irregular closed mesh: the convex hull of 40 random points."""
    rng = np.random.default_rng(SEED)
    return trimesh.convex.convex_hull(rng.uniform(-0.5, 0.5, size=(40, 3)))


@pytest.mark.parametrize("kind", ["stl", "stl_ascii", "obj"])
def test_vertices_match_trimesh(tmp_path: Path, mesh: object, kind: str) -> None:
    suffix = "obj" if kind == "obj" else "stl"
    path = tmp_path / f"m.{suffix}"
    data = trimesh.exchange.export.export_mesh(mesh, file_type=kind, file_obj=None)
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    got = read_vertices(path, str(tmp_path / "r.urdf"))
    assert got is not None
    ref = np.asarray(trimesh.load(str(path), force="mesh", process=False).vertices)
    # The same point sets (an STL repeats each corner per face; trimesh merges them).
    assert np.unique(np.round(got, 6), axis=0) == pytest.approx(
        np.unique(np.round(ref, 6), axis=0), abs=EXACT
    )
    assert got[:, 2].min() == pytest.approx(ref[:, 2].min(), abs=EXACT)  # what contacts use


def test_unreadable_and_missing_files_give_no_points(tmp_path: Path) -> None:
    (tmp_path / "bad.stl").write_bytes(b"not a mesh at all")
    assert read_vertices(tmp_path / "bad.stl", "r.urdf") is None
    assert read_vertices(tmp_path / "absent.stl", "r.urdf") is None
