"""Rules on the Pinocchio model: gravity versus effort, PD stability, self-collision.

The worst gravity torque over a sample of the joint range is compared with the effort
limit, PD stability is checked at the spec's time step (armcli.sim.stability), and
self-collision at the spec's named poses (Pinocchio GeometryModel + coal).
"""

from __future__ import annotations

import itertools
import random
from dataclasses import replace
from typing import Any

import numpy as np

from armcli.check.rules import CheckOptions, Collector, JointRow
from armcli.check.structure import finite
from armcli.errors import InputError
from armcli.sim import stability as stab
from armcli.sim.stability import StabilityReport
from armcli.urdf.doc import Urdf
from armcli.urdf.mesh_confine import bounded_mesh_file, check_total, with_real_mesh_paths
from armcli.urdf.meshes import mesh_paths
from armcli.urdf.pinocchio import collision_model, configuration, mass_matrix

GRID_POINTS = 5  # per joint, when the grid has at most MAX_GRID samples
MAX_GRID = 125
MAX_CORNERS = 64  # every corner of the range box when there are at most this many
RANDOM_SAMPLES = 100
SAMPLE_SEED = 0
# Shapes must overlap by more than this to count as colliding: links that merely
# touch by construction (e.g. a link resting on the base top) are not a collision.
PENETRATION_TOL = 1e-4  # [m]
# Remedies: an effort limit covering the worst gravity torque with this margin (payload,
# acceleration), and time steps / gains this fraction inside the strict stability bounds,
# both rounded to 2 significant digits (up for effort, down for dt, Kd and Kp).
EFFORT_MARGIN = 1.5
STABLE_MARGIN = 0.9
REMEDY_DIGITS = 2


def round_up(x: float, digits: int = REMEDY_DIGITS) -> float:
    """X rounded up to `digits` significant digits (an effort that still covers x)."""
    if x <= 0 or not np.isfinite(x):
        return x
    step = 10.0 ** (np.floor(np.log10(x)) - digits + 1)
    return float(f"{np.ceil(x / step - 1e-9) * step:.{digits}g}")


def round_down(x: float, digits: int = REMEDY_DIGITS) -> float:
    """X rounded down to `digits` significant digits (a dt or gain still below a bound)."""
    if x <= 0 or not np.isfinite(x):
        return x
    step = 10.0 ** (np.floor(np.log10(x)) - digits + 1)
    return float(f"{np.floor(x / step + 1e-9) * step:.{digits}g}")


def samples(model: Any, ranges: list[Any]) -> list[tuple[dict[str, float], Any]]:
    """Joint-space sample as (joint values by name, Pinocchio configuration) pairs.

    A full grid for few joints; else the zero pose clamped into range, every corner of the
    range box (where gravity torques peak for serial arms) when there are few, and seeded
    draws, so the same URDF always gives the same sample.
    """
    n = len(ranges)
    names = [jr.name for jr in ranges]
    if n and GRID_POINTS**n <= MAX_GRID:
        axes = [np.linspace(jr.lower, jr.upper, GRID_POINTS) for jr in ranges]
        points = [dict(zip(names, map(float, p), strict=True)) for p in itertools.product(*axes)]
    else:
        rng = random.Random(SAMPLE_SEED)  # stdlib: numpy.random costs 20 ms of start-up
        rows = [[min(max(0.0, jr.lower), jr.upper) for jr in ranges]]
        if 2**n <= MAX_CORNERS:
            rows += [list(c) for c in itertools.product(*[(jr.lower, jr.upper) for jr in ranges])]
        rows += [[rng.uniform(jr.lower, jr.upper) for jr in ranges] for _ in range(RANDOM_SAMPLES)]
        points = [dict(zip(names, r, strict=True)) for r in rows]
    return [(p, configuration(model, p)) for p in points]


def gravity(
    urdf: Urdf,
    model: Any,
    data: Any,
    samples: list[Any],
    rows: tuple[JointRow, ...],
    out: Collector,
) -> tuple[JointRow, ...]:
    """Rule `gravity-effort`: the worst gravity torque over `samples` versus each effort limit.

    Returns:
        `rows` with `gravity_max` [N·m or N] filled in (None for joints not in the model).
    """
    import pinocchio as pin

    worst = np.zeros(model.nv)
    for _, q in samples:
        worst = np.maximum(worst, np.abs(pin.computeGeneralizedGravity(model, data, q)))
    by_name = {
        str(model.names[j]): model.joints[j].idx_v
        for j in range(1, model.njoints)
        if model.joints[j].nv == 1
    }
    lines = {j.name: (j.limit.line if j.limit else j.line) for j in urdf.joints}
    new_rows = []
    for r in rows:
        g = float(worst[by_name[r.name]]) if r.name in by_name else None
        if g is not None and r.effort is not None and finite(r.effort) and g > r.effort > 0:
            effort = round_up(EFFORT_MARGIN * g)
            out.add(
                "gravity-effort",
                lines.get(r.name),
                f"joint {r.name!r}: gravity torque "
                f"up to {g:.4g} exceeds the effort limit {r.effort:g}; "
                f'effort="{effort:g}" covers it with a {EFFORT_MARGIN:g}x margin',
                {"effort": effort},
                joint=r.name,
                gravity_max=g,
                effort=r.effort,
            )
        new_rows.append(replace(r, gravity_max=g))
    return tuple(new_rows)


def stability(
    urdf: Urdf,
    opts: CheckOptions,
    model: Any,
    data: Any,
    samples: list[Any],
    ranges: list[Any],
    out: Collector,
    notes: list[str],
) -> StabilityReport | None:
    """Rules `pd-explicit-unstable` and `pd-unstable`: the spec's PD gains at its time step.

    The mass matrix at every sample bounds the gains (armcli.sim.stability). Returns None
    without a spec that has gains, and adds a note when no controlled joint is in the URDF.
    """
    spec = opts.spec
    if spec is None or not spec.control.gains:
        return None
    v_of = {jr.name: jr.idx_v for jr in ranges}
    joints = {j.name: j for j in urdf.joints}
    names = [n for n in spec.control.gains if n in v_of and n in joints]
    if not names:
        notes.append("stability skipped: no controlled joint found in this URDF")
        return None
    Ms = [mass_matrix(model, data, q) for _, q in samples]
    qs = [[p[n] for n in names] for p, _ in samples]
    gains = [spec.control.gains[n] for n in names]
    rep = stab.analyse(
        Ms,
        qs,
        [v_of[n] for n in names],
        [g.kp for g in gains],
        [g.kd for g in gains],
        [joints[n].damping for n in names],
        spec.control.dt,
    )
    line = next((j.line for j in urdf.joints if j.name == names[0]), None)
    _report_stability(rep, names, line, out)
    return rep


def _report_stability(
    rep: StabilityReport, names: list[str], line: int | None, out: Collector
) -> None:
    """The two PD findings, with the numbers that explain them and a remedy."""
    q_txt = ", ".join(f"{n} = {v:.3g}" for n, v in zip(names, rep.q_worst, strict=True))
    common = dict(lambda_max=rep.lambda_max, dt=rep.dt, kp=rep.kp, kd_plus_damping=rep.d)
    if not rep.explicit.stable:
        e = rep.explicit
        fix = {
            "dt": round_down(STABLE_MARGIN * e.dt_max),
            "kd": round_down(STABLE_MARGIN * rep.kd_max_explicit),
        }
        out.add(
            "pd-explicit-unstable",
            line,
            f"explicit-damping PD at dt = {rep.dt:g} s diverges: "
            f"lambda_max(M^-1) = {rep.lambda_max:.4g} at {q_txt}; (Kd+damping)*dt*lambda = "
            f"{e.b:.3g}, Kp*dt^2*lambda = {e.a:.3g}, need a + 2b < 4 (is {e.a + 2 * e.b:.3g}); "
            f"stable for dt < {e.dt_max:.3g} s or Kd < {rep.kd_max_explicit:.3g}"
            + (
                f"; with implicit damping (as `armcli simulate` steps) it is stable for "
                f"Kp < {rep.kp_max_implicit:.4g}"
                if rep.implicit.stable
                else ""
            )
            + f"; e.g. dt = {fix['dt']:g} s or Kd = {fix['kd']:g}",
            fix,
            **common,
            a=e.a,
            b=e.b,
            dt_max=e.dt_max,
            kd_max=rep.kd_max_explicit,
        )
    if not rep.implicit.stable:
        fix = {
            "dt": round_down(STABLE_MARGIN * rep.implicit.dt_max),
            "kp": round_down(STABLE_MARGIN * rep.kp_max_implicit),
        }
        out.add(
            "pd-unstable",
            line,
            f"PD at dt = {rep.dt:g} s diverges even with implicit "
            f"damping: Kp = {rep.kp:g} > {rep.kp_max_implicit:.4g}; stable for dt < "
            f"{rep.implicit.dt_max:.3g} s; e.g. dt = {fix['dt']:g} s or Kp = {fix['kp']:g}",
            fix,
            **common,
            kp_max=rep.kp_max_implicit,
            dt_max=rep.implicit.dt_max,
        )


def self_collision(
    urdf: Urdf,
    opts: CheckOptions,
    model: Any,
    poses: list[tuple[str, dict[str, float]]],
    out: Collector,
    notes: list[str],
) -> None:
    """Rule `self-collision`: link pairs that interpenetrate at the spec's named poses.

    Adjacent (parent-child) links and overlaps below PENETRATION_TOL [m] do not count. Skipped
    with a note when a mesh cannot be found or the collision model cannot be built.
    """
    import pinocchio as pin

    meshes = mesh_paths(urdf, opts.mesh_search())
    if any(p is None or not p.is_file() for p in meshes.values()):
        notes.append("self-collision skipped: some meshes cannot be found")
        return
    real = {uri: bounded_mesh_file(p, urdf.source) for uri, p in meshes.items() if p is not None}
    check_total(real.values(), urdf.source)
    try:  # Pinocchio gets absolute confined paths and no search directories
        gmodel = collision_model(model, with_real_mesh_paths(urdf.text, real), [])
    except InputError as exc:
        notes.append(f"self-collision skipped: {exc.message}")
        return
    link_of = [str(model.frames[g.parentFrame].name) for g in gmodel.geometryObjects]
    adjacent = {frozenset((j.parent, j.child)) for j in urdf.joints}
    pairs = []
    for i, k in itertools.combinations(range(len(link_of)), 2):
        if link_of[i] != link_of[k] and frozenset((link_of[i], link_of[k])) not in adjacent:
            gmodel.addCollisionPair(pin.CollisionPair(i, k))
            pairs.append((link_of[i], link_of[k]))
    gdata = pin.GeometryData(gmodel)
    for req, pair in zip(gdata.collisionRequests, gmodel.collisionPairs, strict=True):
        # coal refuses negative margins on meshes ("not handled yet for BVHModel"): there,
        # touching counts as colliding.
        meshy = _is_mesh(gmodel, pair.first) or _is_mesh(gmodel, pair.second)
        req.security_margin = 0.0 if meshy else -PENETRATION_TOL
    data = model.createData()
    named = [p for p in poses if p[0] in (opts.spec.poses if opts.spec else {})]
    for name, values in named:
        pin.computeCollisions(model, data, gmodel, gdata, configuration(model, values), False)
        for k, (a, b) in enumerate(pairs):
            if gdata.collisionResults[k].isCollision():
                out.add(
                    "self-collision",
                    _link_line(urdf, a),
                    f"pose {name!r}: {a!r} and {b!r} collide",
                    pose=name,
                    link1=a,
                    link2=b,
                )


def _is_mesh(gmodel: Any, index: int) -> bool:
    import coal

    geometry = gmodel.geometryObjects[index].geometry
    return bool(geometry.getObjectType() == coal.OBJECT_TYPE.OT_BVH)


def _link_line(urdf: Urdf, name: str) -> int | None:
    return next((lk.line for lk in urdf.links if lk.name == name), None)
