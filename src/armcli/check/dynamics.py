"""Rules on the Pinocchio model: gravity versus effort, PD stability, self-collision.

The worst gravity torque over a sample of the joint range is compared with the effort
limit, PD stability is checked at the spec's time step (armcli.analysis.stability), and
self-collision at the spec's named poses (Pinocchio GeometryModel + coal).
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.analysis import pdloop
from armcli.analysis import verdict as verdicts
from armcli.analysis.verdict import StabilityReport
from armcli.check.findings import Collector, JointRow, Value
from armcli.check.options import CheckOptions
from armcli.check.structure import finite
from armcli.errors import ModelLoadError
from armcli.robot.collision import SelfCollision
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import mesh_paths

if TYPE_CHECKING:  # a URDF's check loads no spec models (pydantic)
    from armcli.spec.model import RobotSpec

# Shapes must overlap by more than this to count as colliding: links that merely
# touch by construction (e.g. a link resting on the base top) are not a collision.
PENETRATION_TOL = 1e-4  # [m]
# Remedy: an effort limit covering the worst gravity torque with this margin (payload,
# acceleration), rounded up to 2 significant digits (stability remedies: analysis.stability).
EFFORT_MARGIN = 1.5
REMEDY_DIGITS = 2


def round_up(x: float, digits: int = REMEDY_DIGITS) -> float:
    """X rounded up to `digits` significant digits (an effort that still covers x)."""
    if x <= 0 or not np.isfinite(x):
        return x
    step = 10.0 ** (np.floor(np.log10(x)) - digits + 1)
    return float(f"{np.ceil(x / step - 1e-9) * step:.{digits}g}")


def gravity(
    urdf: Urdf,
    robot: Robot,
    samples: list[Any],
    rows: tuple[JointRow, ...],
    out: Collector,
) -> tuple[JointRow, ...]:
    """Rule `gravity-effort`: the worst gravity torque over `samples` versus each effort limit.

    Returns:
        `rows` with `gravity_max` [N·m or N] filled in (None for joints not in the model).
    """
    worst = np.zeros(robot.model.nv)
    for _, q in samples:
        worst = np.maximum(worst, np.abs(robot.gravity(q)))
    by_name = {j.name: j.idx_v for j in robot.joints}
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
    robot: Robot,
    samples: list[Any],
    out: Collector,
    notes: list[str],
) -> StabilityReport | None:
    """Rules `pd-explicit-unstable` and `pd-unstable`: the spec's PD gains at its time step.

    M(q) and gravity's stiffness at every sample bound the gains (armcli.analysis.stability).
    Returns None without a spec that has gains, and adds a note when no controlled joint
    is in the URDF.
    """
    spec = opts.spec
    if spec is None or not spec.control.gains:
        return None
    controlled = spec_pd(urdf, spec, robot)
    if controlled is None:
        notes.append("stability skipped: no controlled joint found in this URDF")
        return None
    names, pd = controlled
    gravity = not spec.control.gravity_compensation
    lin = pdloop.linearise(robot, [q for _, q in samples], gravity=gravity)
    qs = [[p[n] for n in names] for p, _ in samples]
    rep = verdicts.analyse(lin, qs, pd, spec.control.dt)
    line = next((j.line for j in urdf.joints if j.name == names[0]), None)
    _report_stability(rep, names, qs, line, out)
    return rep


def spec_pd(urdf: Urdf, spec: RobotSpec, robot: Robot) -> tuple[list[str], pdloop.PD] | None:
    """The spec's gained joints that this URDF has, and their PD gains (None: none of them)."""
    v_of = {j.name: j.idx_v for j in robot.joints}
    joints = {j.name: j for j in urdf.joints}
    names = [n for n in spec.control.gains if n in v_of and n in joints]
    if not names:
        return None
    gains = [spec.control.gains[n] for n in names]
    pd = pdloop.PD.of(
        [v_of[n] for n in names],
        [g.kp for g in gains],
        [g.kd for g in gains],
        [joints[n].damping for n in names],
    )
    return names, pd


def _report_stability(
    rep: StabilityReport,
    names: list[str],
    qs: list[list[float]],
    line: int | None,
    out: Collector,
) -> None:
    """One finding per unstable loop, saying which loop, why, where and its one remedy."""
    common = dict(
        lambda_max=rep.lambda_max,
        dt=rep.dt,
        kp=rep.kp,
        kd_plus_damping=rep.d,
        gravity_stiffness=rep.gravity_stiffness,
    )
    numbers = (rep.kp, rep.d, rep.gravity_stiffness, rep.lambda_max)
    for rule, v in (("pd-unstable", rep.implicit), ("pd-explicit-unstable", rep.explicit)):
        if v.stable or v.suggestion is None:
            continue
        text = verdicts.message(v, names, qs[v.worst], rep.dt, numbers)
        if rule == "pd-explicit-unstable" and rep.implicit.stable:
            text += f"; {rep.implicit.loop} is stable with these gains"
        fix: dict[str, Value] = {"dt": v.suggestion.dt}
        if v.suggestion.kp is not None and v.suggestion.kd is not None:
            fix["kp"], fix["kd"] = list(v.suggestion.kp), list(v.suggestion.kd)
        out.add(
            rule, line, text, fix, **common, a=v.a, b=v.b, dt_max=v.dt_max, gain_scale=v.gain_scale
        )


def self_collision(
    urdf: Urdf,
    opts: CheckOptions,
    robot: Robot,
    poses: list[tuple[str, dict[str, float]]],
    out: Collector,
    notes: list[str],
) -> None:
    """Rule `self-collision`: link pairs that interpenetrate at the spec's named poses.

    Adjacent (parent-child) links and overlaps below PENETRATION_TOL [m] do not count. Skipped
    with a note when a mesh cannot be found or the collision model cannot be built.
    """
    search = opts.mesh_search()
    if any(p is None or not p.is_file() for p in mesh_paths(urdf, search).values()):
        notes.append("self-collision skipped: some meshes cannot be found")
        return
    try:  # Pinocchio gets absolute confined paths and no search directories
        gmodel = robot.collision_model(search)
    except ModelLoadError as exc:
        notes.append(f"self-collision skipped: {exc.message}")
        return
    adjacent = {frozenset((j.parent, j.child)) for j in urdf.joints}
    check = SelfCollision(robot, lambda a, b: frozenset((a, b)) not in adjacent, gmodel)
    for req, (i, k) in zip(check.gdata.collisionRequests, check.objects, strict=True):
        # coal refuses negative margins on meshes ("not handled yet for BVHModel"): there,
        # touching counts as colliding.
        meshy = _is_mesh(gmodel, i) or _is_mesh(gmodel, k)
        req.security_margin = 0.0 if meshy else -PENETRATION_TOL
    named = [p for p in poses if p[0] in (opts.spec.poses if opts.spec else {})]
    for name, values in named:
        for a, b in (check.pairs[k] for k in check.colliding(robot.q(values))):
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
