"""Support polygon maths: the hull against scipy's Qhull, margins against geometry."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from armcli.analysis.support import convex_hull, direction_name, support_polygon

TOL = 1e-12  # [m] plain arithmetic on coordinates of order 1


def test_hull_equals_qhull_on_random_clouds() -> None:
    rng = random.Random(1)
    for _ in range(50):
        pts = [(rng.uniform(-1, 1), rng.uniform(-1, 1)) for _ in range(rng.randint(3, 40))]
        ours = convex_hull(pts)
        qhull = ConvexHull(np.array(pts))  # the reference: Qhull's vertices, counter-clockwise
        ref = [tuple(map(float, np.array(pts)[i])) for i in qhull.vertices]
        start = ref.index(ours[0])
        assert ours == ref[start:] + ref[:start]


def test_square_margins_and_directions() -> None:
    poly = support_polygon([(1, 1, 0), (-1, 1, 0), (-1, -1, 0), (1, -1, 0), (0, 1, 0)])
    assert poly is not None
    assert len(poly.vertices) == 4  # the point on an edge is dropped
    assert poly.area == pytest.approx(4.0, abs=TOL)
    assert sorted(e.direction for e in poly.edges) == ["front", "left", "rear", "right"]
    # inside: distance to the nearest side; outside beyond a corner: Euclidean to the corner
    assert poly.margin((0.25, 0.5)) == pytest.approx(0.5, abs=TOL)
    assert poly.margin((2.0, 3.0)) == pytest.approx(-math.hypot(1.0, 2.0), abs=TOL)
    assert poly.margin((0.0, -1.5)) == pytest.approx(-0.5, abs=TOL)
    assert poly.edges[poly.nearest_edge((0.9, 0.0))].direction == "front"


def test_degenerate_contacts_give_no_polygon() -> None:
    assert support_polygon([(0, 0), (1, 0)]) is None  # two wheels, no caster
    assert support_polygon([(0, 0), (1, 0), (2, 0), (3, 0)]) is None  # all on one line


@pytest.mark.parametrize(
    ("deg", "name"),
    [
        (0, "front"),
        (44, "front-left"),
        (90, "left"),
        (180, "rear"),
        (-90, "right"),
        (-135, "rear-right"),
    ],
)
def test_direction_names(deg: float, name: str) -> None:
    assert direction_name(math.radians(deg)) == name


def test_margins_at_once_equal_shapely_distances() -> None:
    """`margins` (the zero-moment point series' vectorised margin) against shapely's geometry:
    inside, the distance to the boundary; outside, minus the distance to the polygon."""
    shapely = pytest.importorskip("shapely")
    rng = np.random.default_rng(3)
    poly = support_polygon([(x, y, 0.0) for x, y in rng.uniform(-1, 1, size=(9, 2))])
    assert poly is not None
    ref = shapely.geometry.Polygon(poly.vertices)
    points = rng.uniform(-2, 2, size=(500, 2))
    got = poly.margins(points)
    for p, m in zip(points, got, strict=True):
        pt = shapely.geometry.Point(p)
        want = ref.exterior.distance(pt) if ref.contains(pt) else -ref.distance(pt)
        assert m == pytest.approx(want, abs=TOL)
        assert m == pytest.approx(poly.margin(p), abs=TOL)  # the one-point margin
    assert poly.margins(np.array([[np.nan, 0.0]]))[0] == -math.inf
