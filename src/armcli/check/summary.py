"""Loading the Pinocchio model for `check`, and the report's summary.

Parser messages become findings. The summary holds mass, DoF, the joint table and the
end-effector forward kinematics at each pose. The model-based rules themselves are in
`armcli.check.dynamics`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from armcli.check import dynamics as dyn
from armcli.check import interface
from armcli.check.rules import CheckOptions, Collector, JointRow
from armcli.check.structure import Tree, finite
from armcli.errors import ModelLoadError
from armcli.sim.verdict import StabilityReport
from armcli.urdf.doc import Urdf
from armcli.urdf.pinocchio import configuration, joint_ranges, load_model, parser_problems
from armcli.urdf.tool import tool_point

# Skip the model after these: urdfdom would only repeat them (a NaN mass came back as
# two parser errors; a nameless <robot> as model-load).
_STRUCTURE_ERRORS = (
    "robot-name",
    "duplicate-name",
    "number-syntax",
    "non-finite",
    "vector-length",
    "unknown-link",
    "multiple-parents",
    "root-count",
    "disconnected",
    "joint-type",
    "missing-limit",
    "mimic-target",
)
_NUMBER_ERRORS = (
    "number-syntax",
    "non-finite",
    "vector-length",
    "mass-nonpositive",
    "inertia-not-pd",
    "inertia-triangle",
    "axis",
    "limit-order",
)


@dataclass(frozen=True)
class PoseRow:
    """One pose in the summary: its joint values [rad or m] and the end-effector position."""

    name: str
    q: tuple[tuple[str, float], ...]
    xyz: tuple[float, float, float]  # end effector in the root link frame [m]


@dataclass(frozen=True)
class Summary:
    """The report's summary of one URDF: mass, DoF, joint table, poses, PD stability, notes."""

    robot: str
    root: str | None
    total_mass: float  # [kg]
    dof: int
    joints: tuple[JointRow, ...]
    end_effector: str
    poses: tuple[PoseRow, ...]
    stability: StabilityReport | None
    notes: tuple[str, ...]


def check(urdf: Urdf, tree: Tree, opts: CheckOptions, out: Collector) -> Summary:
    """Load the Pinocchio model, run the model rules on it and build the summary.

    Parser messages become `parser-error`/`parser-message` findings and a refused model a
    `model-load` finding; the model is not loaded while structure errors remain.
    """
    rows = _joint_rows(urdf)
    base: dict[str, Any] = {
        "robot": urdf.name,
        "root": tree.root,
        "total_mass": _total_mass(urdf),
        "dof": sum(1 for r in rows),
    }
    if out.has_errors(_STRUCTURE_ERRORS):
        note = "model checks skipped: fix the structure errors first"
        return Summary(
            **base, joints=rows, end_effector="", poses=(), stability=None, notes=(note,)
        )

    try:
        loaded = load_model(urdf.source, xml=urdf.text.decode("utf-8"))
    except ModelLoadError as exc:
        out.add("model-load", None, exc.message)
        return Summary(**base, joints=rows, end_effector="", poses=(), stability=None, notes=())
    for msg in parser_problems(loaded.parser_messages):
        rule = "parser-error" if msg.lower().startswith("error") else "parser-message"
        out.add(rule, None, f"Pinocchio/urdfdom: {msg}", text=msg)
    return _with_model(urdf, tree, opts, out, loaded.model, rows, base)


def _with_model(
    urdf: Urdf,
    tree: Tree,
    opts: CheckOptions,
    out: Collector,
    model: Any,
    rows: tuple[JointRow, ...],
    base: dict[str, Any],
) -> Summary:
    import pinocchio as pin

    data = model.createData()
    ranges = joint_ranges(model)
    notes: list[str] = []
    ee_label, ee_frame, ee_offset = _end_effector(urdf, opts, model)
    poses = _poses(urdf, opts, ranges)
    pose_rows = []
    for name, values in poses:
        q = configuration(model, values)
        pin.framesForwardKinematics(model, data, q)
        xyz = data.oMf[ee_frame].act(np.asarray(ee_offset, dtype=float))
        pose_rows.append(PoseRow(name, tuple(values.items()), tuple(float(x) for x in xyz)))  # type: ignore[arg-type]
    report = None
    if out.has_errors(_NUMBER_ERRORS):
        notes.append("dynamics checks skipped: fix the number and inertia errors first")
    else:
        samples = dyn.samples(model, ranges)
        rows = dyn.gravity(urdf, model, data, samples, rows, out)
        servo = interface.check(urdf.text, opts, out, notes)
        gained = set(opts.spec.control.gains) if opts.spec is not None else set()
        if not (servo and gained <= servo):  # a position servo is not a PD loop
            report = dyn.stability(urdf, opts, model, samples, ranges, out, notes)
    if opts.spec is not None and opts.spec.poses:
        dyn.self_collision(urdf, opts, model, poses, out, notes)
    return Summary(
        **base,
        joints=rows,
        end_effector=ee_label,
        poses=tuple(pose_rows),
        stability=report,
        notes=tuple(notes),
    )


def _total_mass(urdf: Urdf) -> float:
    masses = (lk.inertial.mass for lk in urdf.links if lk.inertial is not None)
    return math.fsum(m for m in masses if m is not None and finite(m) and m > 0)


def _joint_rows(urdf: Urdf) -> tuple[JointRow, ...]:
    rows = []
    for j in urdf.joints:
        if j.type in ("fixed", ""):
            continue
        lim = j.limit
        rows.append(
            JointRow(
                j.name,
                j.type,
                lim.lower if lim and j.type != "continuous" else None,
                lim.upper if lim and j.type != "continuous" else None,
                lim.effort if lim else None,
                lim.velocity if lim else None,
                j.damping,
                j.friction,
            )
        )
    return tuple(rows)


def _end_effector(
    urdf: Urdf, opts: CheckOptions, model: Any
) -> tuple[str, int, tuple[float, float, float]]:
    """The tool point (armcli.urdf.tool) as (label, Pinocchio frame id, offset [m])."""
    tool = tool_point(urdf, opts.spec)
    if tool is None or not model.existFrame(tool.link):
        name = str(model.frames[0].name)
        return name, model.getFrameId(name), (0.0, 0.0, 0.0)
    label = f"{tool.link} + {tool.xyz}" if tool.xyz != (0.0, 0.0, 0.0) else tool.link
    return label, model.getFrameId(tool.link), tool.xyz


def _poses(urdf: Urdf, opts: CheckOptions, ranges: list[Any]) -> list[tuple[str, dict[str, float]]]:
    """Named poses of the spec (or q = 0), then every joint at its lower and upper limit."""
    out: list[tuple[str, dict[str, float]]] = []
    spec = opts.spec
    if spec is not None and spec.poses:
        names = {jr.name for jr in ranges}
        for name in spec.poses:
            out.append((name, {k: v for k, v in spec.pose(name).items() if k in names}))
    else:
        out.append(("zero", {jr.name: 0.0 for jr in ranges}))
    limited = [jr for jr in ranges if not jr.continuous]
    if limited:
        out.append(("lower", {jr.name: jr.lower for jr in limited}))
        out.append(("upper", {jr.name: jr.upper for jr in limited}))
    return out
