"""An independent 1 kHz check of a planned trajectory: its own reading, interpolation and model.

Nothing of armcli's planner, timing or certification is used. The written document is read
with PyYAML; each segment's quintic is rebuilt from its two points' positions, velocities
and accelerations by solving the 6 x 6 boundary conditions (numpy.linalg.solve, not the
closed forms trajectory.reference uses) and sampled every millisecond with its analytic
derivatives. Positions, velocities and accelerations are compared with the joint limits,
torques (Pinocchio's RNEA on a model built directly from the URDF) with the effort limits,
and every sample is checked for collisions with Pinocchio and coal on geometry loaded
directly from the URDF (meshes through Pinocchio's own loader) plus the scene's
primitives built from its YAML, every link pair the SRDF leaves enabled and every link
against every scene object, queried with contacts (exact; see plan.collision).

Used by tests/plan/test_oracle.py and by bench/bench_plan.py on every benchmark plan.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

RATE_HZ = 1000.0
POSITION_TOL = 1e-6  # [rad] the quintic may dip this far past a limit it leaves from
RELATIVE_TOL = 1e-6  # velocity, acceleration, torque: relative slack on their limits


@dataclass(frozen=True)
class Report:
    """What the check found: counts per kind, and the first violation in words."""

    samples: int
    violations: dict[str, int]
    first: str = ""

    @property
    def ok(self) -> bool:
        return not any(self.violations.values())


Points = tuple[list[str], np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def read_points(document: bytes) -> Points:
    """Joint names, times (P,), positions, velocities, accelerations (P, n): PyYAML's reading."""
    doc = yaml.safe_load(document)
    names = [str(n) for n in doc["joint_names"]]
    pts = doc["points"]

    def rows(key: str) -> np.ndarray:  # YAML 1.1 reads `1e-05` as a string: float() it
        return np.array([[float(v) for v in p[key]] for p in pts])

    stamps = [p["time_from_start"] for p in pts]
    t = np.array([s["sec"] + s["nanosec"] * 1e-9 for s in stamps])
    return names, t, rows("positions"), rows("velocities"), rows("accelerations")


def quintic(h: float, p0: np.ndarray, v0: np.ndarray, a0: np.ndarray, p1: np.ndarray,
            v1: np.ndarray, a1: np.ndarray) -> np.ndarray:  # fmt: skip
    """(6, n) coefficients of q(tau) = sum c_k tau^k on [0, h] meeting both ends' values."""
    M = np.array([
        [1, 0, 0, 0, 0, 0],
        [0, 1, 0, 0, 0, 0],
        [0, 0, 2, 0, 0, 0],
        [1, h, h**2, h**3, h**4, h**5],
        [0, 1, 2 * h, 3 * h**2, 4 * h**3, 5 * h**4],
        [0, 0, 2, 6 * h, 12 * h**2, 20 * h**3],
    ], dtype=float)  # fmt: skip
    return np.linalg.solve(M, np.vstack([p0, v0, a0, p1, v1, a1]))


def sampled(t: np.ndarray, P: np.ndarray, V: np.ndarray, A: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Times, positions, velocities, accelerations at RATE_HZ (the last point included)."""
    ts = np.append(np.arange(math.floor(t[-1] * RATE_HZ) + 1) / RATE_HZ, t[-1])
    seg = np.clip(np.searchsorted(t, ts, side="right") - 1, 0, len(t) - 2)
    coeffs = [quintic(t[k + 1] - t[k], P[k], V[k], A[k], P[k + 1], V[k + 1], A[k + 1])
              for k in range(len(t) - 1)]  # fmt: skip
    q, v, a = (np.empty((len(ts), P.shape[1])) for _ in range(3))
    for i, (time, k) in enumerate(zip(ts, seg, strict=True)):
        c, u = coeffs[k], time - t[k]
        q[i] = sum(c[j] * u**j for j in range(6))
        v[i] = sum(j * c[j] * u ** (j - 1) for j in range(1, 6))
        a[i] = sum(j * (j - 1) * c[j] * u ** (j - 2) for j in range(2, 6))
    return ts, q, v, a


def _scene_shapes(scene: Path | None) -> list[tuple[str, Any, Any]]:
    """(object id, coal shape, placement) for every primitive of a PlanningScene YAML."""
    import coal
    import pinocchio as pin

    if scene is None:
        return []
    doc = yaml.safe_load(scene.read_text())
    objects = doc.get("world", doc)["collision_objects"]
    out = []
    make = {"box": lambda d: coal.Box(*d), "sphere": lambda d: coal.Sphere(d[0]),
            "cylinder": lambda d: coal.Cylinder(d[1], d[0])}  # fmt: skip

    def pose(p: dict[str, Any] | None) -> Any:
        p = p or {}
        xyz = [float((p.get("position") or {}).get(k, 0.0)) for k in "xyz"]
        o = p.get("orientation") or {}
        quat = pin.Quaternion(float(o.get("w", 1.0)), float(o.get("x", 0.0)),
                              float(o.get("y", 0.0)), float(o.get("z", 0.0)))  # fmt: skip
        quat.normalize()
        return pin.SE3(quat.matrix(), np.array(xyz))

    for obj in objects:
        base = pose(obj.get("pose"))
        for prim, p in zip(obj["primitives"], obj["primitive_poses"], strict=True):
            out.append((obj["id"], make[prim["type"]]([float(d) for d in prim["dimensions"]]),
                        base * pose(p)))  # fmt: skip
    return out


class Oracle:
    """A robot (URDF, SRDF, package directories) and a scene, checked independently."""

    def __init__(self, urdf: Path, srdf: Path | None, package_dirs: list[str],
                 scene: Path | None, acceleration: dict[str, float]) -> None:  # fmt: skip
        import coal
        import pinocchio as pin

        self.pin = pin
        self.model = pin.buildModelFromUrdf(str(urdf))
        self.data = self.model.createData()
        self.geom = pin.buildGeomFromUrdf(
            self.model, str(urdf), pin.COLLISION, package_dirs=package_dirs
        )
        links = [self.model.frames[g.parentFrame].name for g in self.geom.geometryObjects]
        for oid, shape, M in _scene_shapes(scene):
            self.geom.addGeometryObject(pin.GeometryObject(oid, 0, 0, M, shape))
            links.append("scene:" + oid)
        disabled = set()
        if srdf is not None:
            for el in ET.parse(srdf).getroot().iter("disable_collisions"):
                disabled.add(frozenset((el.get("link1"), el.get("link2"))))
        for i in range(len(links)):
            for j in range(i + 1, len(links)):
                a, b = links[i], links[j]
                if a == b or frozenset((a, b)) in disabled:
                    continue
                if a.startswith("scene:") and b.startswith("scene:"):
                    continue
                self.geom.addCollisionPair(pin.CollisionPair(i, j))
        self.links = links
        self.gdata = pin.GeometryData(self.geom)
        for req in self.gdata.collisionRequests:
            req.enable_contact = True
        # Pinocchio's own broadphase (coal's dynamic AABB tree): the same verdicts as every
        # pair, without coal refitting a box around a primitive for each mesh query
        self.manager = pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(
            self.model, self.geom, self.gdata
        )
        self.acceleration = acceleration
        del coal

    def q(self, names: list[str], x: np.ndarray) -> np.ndarray:
        """The configuration: named joints at x, the others at 0 (or their range's middle)."""
        m, q = self.model, self.pin.neutral(self.model)
        for jid in range(1, m.njoints):
            j = m.joints[jid]
            if j.nq == 1:
                lo, hi = m.lowerPositionLimit[j.idx_q], m.upperPositionLimit[j.idx_q]
                q[j.idx_q] = 0.0 if lo <= 0.0 <= hi else 0.5 * (lo + hi)
        for name, value in zip(names, x, strict=True):
            q[m.joints[m.getJointId(name)].idx_q] = value
        return q

    def check(self, document: bytes) -> Report:
        """Every sample at 1 kHz against every limit and for collisions."""
        pin, m = self.pin, self.model
        names, t, P, V, A = read_points(document)
        ts, q, v, a = sampled(t, P, V, A)
        ids = [m.getJointId(n) for n in names]
        iq = [m.joints[j].idx_q for j in ids]
        iv = [m.joints[j].idx_v for j in ids]
        lo, hi = m.lowerPositionLimit[iq], m.upperPositionLimit[iq]
        vmax, emax = m.velocityLimit[iv], m.effortLimit[iv]
        amax = np.array([self.acceleration[n] for n in names])
        found: dict[str, int] = {}
        first = ""

        def note(kind: str, k: int, what: str) -> None:
            nonlocal first
            found[kind] = found.get(kind, 0) + 1
            first = first or f"{kind} at t = {ts[k]:.3f} s: {what}"

        for k in range(len(ts)):
            if np.any(q[k] < lo - POSITION_TOL) or np.any(q[k] > hi + POSITION_TOL):
                note("position", k, str(q[k]))
            if np.any(np.abs(v[k]) > vmax * (1 + RELATIVE_TOL)):
                note("velocity", k, str(v[k]))
            if np.any(np.abs(a[k]) > amax * (1 + RELATIVE_TOL)):
                note("acceleration", k, str(a[k]))
            qf = self.q(names, q[k])
            vf, af = np.zeros(m.nv), np.zeros(m.nv)
            vf[iv], af[iv] = v[k], a[k]
            tau = pin.rnea(m, self.data, qf, vf, af)[iv]
            if np.any(np.abs(tau) > emax * (1 + RELATIVE_TOL)):
                note("effort", k, str(tau))
            pin.updateGeometryPlacements(m, self.data, self.geom, self.gdata, qf)
            self.manager.update(False)
            if pin.computeCollisions(self.manager, True):
                pair = next(cp for cp, r in zip(self.geom.collisionPairs,
                                                self.gdata.collisionResults, strict=True)
                            if r.isCollision())  # fmt: skip
                note("collision", k, f"{self.links[pair.first]} and {self.links[pair.second]}")
        return Report(len(ts), {k: found.get(k, 0) for k in
                                ("position", "velocity", "acceleration", "effort", "collision")},
                      first)  # fmt: skip
