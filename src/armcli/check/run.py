"""Run every `check` rule family on one parsed URDF, in the fixed order of `FAMILIES`.

The structure rules come first (every other family needs the kinematic tree they
build); then each family of the registry, in order, once the stage it needs is there
(check/context.py: the model loads once, lazily, unless a blocking error stands). A new
rule family is a module with a function of the `Context` and one line in `FAMILIES`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

from armcli.check import (
    bodies,
    controller_rate,
    inertia,
    interface,
    joints,
    meshes,
    reach,
    sensors,
    structure,
    summary,
    tipover,
)
from armcli.check import dynamics as dyn
from armcli.check import zmp as zmp_rules
from armcli.check.context import (
    BALANCE,
    BLOCKS_DYNAMICS,
    BLOCKS_MODEL,
    DYNAMICS,
    DYNAMICS_SKIPPED,
    MODEL,
    MODEL_SKIPPED,
    URDF,
    Context,
    Stage,
    blocks_balance,
    joint_rows,
    poses,
)
from armcli.check.findings import Collector, Finding
from armcli.check.options import CheckOptions
from armcli.check.rules import RULES
from armcli.check.summary import Summary
from armcli.errors import ModelLoadError
from armcli.robot import sampling
from armcli.robot.load import parser_problems
from armcli.robot.model import Robot
from armcli.urdf.doc import Urdf


@dataclass(frozen=True)
class Family:
    """A group of rules run together: a name, the stage it needs, the function, its rules.

    `rules` lists every rule id the family can report (Collector refuses any other), so a
    caller that wants a few rules runs only the families that can report them
    (`check_rules`: the gate before a run); `uses`, the families whose results it reads.
    """

    name: str
    needs: Stage
    run: Callable[[Context], None]
    rules: frozenset[str] = frozenset()
    uses: tuple[str, ...] = ()


def _gravity(c: Context) -> None:
    c.rows = dyn.gravity(c.urdf, c.loaded(), c.samples, c.rows, c.out)


def _servo(c: Context) -> None:
    c.servo = interface.check(c.urdf, c.opts, c.out, c.notes)


def _stability(c: Context) -> None:
    gained = set(c.opts.spec.control.gains) if c.opts.spec is not None else set()
    if c.servo and gained <= c.servo:  # a position servo is not a PD loop
        return
    c.stability = dyn.stability(c.urdf, c.opts, c.loaded(), c.samples, c.out, c.notes)


def _self_collision(c: Context) -> None:
    if c.opts.spec is not None and c.opts.spec.poses:
        dyn.self_collision(c.urdf, c.opts, c.loaded(), poses(c), c.out, c.notes)


def _rules(ids: str) -> frozenset[str]:
    """A family's rule ids, space-separated (each in check/rules.py's registry)."""
    return frozenset(ids.split())


INERTIA_RULES = _rules(
    "missing-inertial root-inertia mass-nonpositive inertia-not-pd inertia-triangle "
    "inertia-geometry com-geometry inertia-exceeds-geometry inertia-exceeds-visual"
)
JOINT_RULES = _rules("axis axis-unit limit-order limit-degrees limit-effort-velocity spec-limits")
SENSOR_RULES = _rules("sensor-link sensor-rate sensor-fov sensor-range sensor-sees-robot")
FAMILIES: tuple[Family, ...] = (
    Family("inertia", URDF, lambda c: inertia.check(c.urdf, c.tree, c.out), INERTIA_RULES),
    Family(
        "bodies",
        URDF,
        lambda c: bodies.check(c.urdf, c.tree, c.out),
        _rules("mass-nonpositive inertia-not-pd tiny-mass"),
    ),
    Family(
        "joints", URDF, lambda c: joints.check(c.urdf, c.opts.spec, c.out, c.notes), JOINT_RULES
    ),
    Family("meshes", URDF, lambda c: meshes.check(c.urdf, c.opts, c.out), _rules("mesh-missing")),
    Family("gravity", DYNAMICS, _gravity, _rules("gravity-effort")),
    Family("servo", DYNAMICS, _servo, _rules("servo-unstable servo-oscillates")),
    Family(
        "stability", DYNAMICS, _stability, _rules("pd-unstable pd-explicit-unstable"), ("servo",)
    ),
    Family(
        "controller rate", DYNAMICS, controller_rate.check, _rules(controller_rate.RULE), ("servo",)
    ),
    Family("self-collision", MODEL, _self_collision, _rules("self-collision")),
    Family("tipover", BALANCE, tipover.check, _rules("com-outside-support support-margin")),
    Family(
        "zmp", DYNAMICS, zmp_rules.check, _rules("zmp-outside-support zmp-margin"), ("tipover",)
    ),
    Family("reach", MODEL, reach.check, _rules("reach-point"), ("tipover",)),
    Family("sensors", MODEL, sensors.check, SENSOR_RULES),
)


@dataclass(frozen=True)
class CheckResult:
    """The `check` outcome for one file: its findings and the report's summary."""

    file: str
    findings: tuple[Finding, ...]
    summary: Summary | None


def check_urdf(urdf: Urdf, options: CheckOptions | None = None) -> CheckResult:
    """Run every rule on one parsed URDF: the document's families, then the model's."""
    ctx = _run(urdf, options, FAMILIES)
    return CheckResult(urdf.source, _found(ctx), summary.summarise(ctx))


def check_rules(
    urdf: Urdf, options: CheckOptions | None, wanted: Callable[[str], bool]
) -> tuple[Finding, ...]:
    """The findings of only the families that can report a `wanted` rule (no summary).

    What the gate before a run asks (check/gate.py): the errors that refuse it. The
    families that cannot report one (a missing mesh, the gravity load, self-collision at
    the named poses) are not run; nor is the summary. Their findings are the same as
    `check_urdf`'s for every wanted rule (tests/check/test_gate.py).
    """
    return _found(_run(urdf, options, families_for(wanted)))


def families_for(wanted: Callable[[str], bool]) -> tuple[Family, ...]:
    """The families that can report a `wanted` rule, in registry order.

    Also those that report a rule that `blocks` a stage (their errors decide whether the
    later families run at all, as in a full check) and those whose results a chosen
    family reads (`uses`).
    """
    by_name = {f.name: f for f in FAMILIES}
    todo = [f.name for f in FAMILIES if any(wanted(r) or RULES[r].blocks for r in f.rules)]
    chosen: set[str] = set()
    while todo:
        name = todo.pop()
        if name not in chosen:
            chosen.add(name)
            todo += by_name[name].uses
    return tuple(f for f in FAMILIES if f.name in chosen)


def _run(urdf: Urdf, options: CheckOptions | None, families: tuple[Family, ...]) -> Context:
    """Run `families` on one parsed URDF: the document's first, then the model's in order."""
    opts = options or CheckOptions()
    out = Collector(urdf.source)
    ctx = Context(urdf, opts, out, structure.check(urdf, out), rows=joint_rows(urdf))
    for family in sorted(families, key=lambda f: f.needs != URDF):  # the document's first
        if _ready(ctx, family.needs):
            out.declared = family.rules
            family.run(ctx)
            out.declared = None
    _ready(ctx, MODEL)  # the model's own findings (model-load), the summary's poses
    return ctx


def _found(ctx: Context) -> tuple[Finding, ...]:
    return tuple(_at_origin(f, ctx.urdf) for f in ctx.out.findings)


def _at_origin(f: Finding, urdf: Urdf) -> Finding:
    """A finding on a xacro expansion's element, with the line the user wrote it on."""
    origin = urdf.origins.get(f.line) if f.line else None
    return f if origin is None else replace(f, origin=origin)


def check_document(urdf: Urdf, options: CheckOptions | None = None) -> tuple[Finding, ...]:
    """The findings of the rules that read the document alone (no model loaded).

    Fast: what `build` reports of what `check` will say.
    """
    opts = options or CheckOptions()
    out = Collector(urdf.source)
    ctx = Context(urdf, opts, out, structure.check(urdf, out), rows=joint_rows(urdf))
    for family in FAMILIES:
        if family.needs == URDF:
            family.run(ctx)
    return tuple(out.findings)


def _ready(ctx: Context, needs: Stage) -> bool:
    """Whether the stage `needs` is there, reaching it on first demand (see check/context.py)."""
    if needs == URDF:
        return True
    if ctx.stage == "unloaded":
        _load(ctx)
    if ctx.stage == MODEL and needs == DYNAMICS:
        if ctx.out.has_errors(BLOCKS_DYNAMICS):
            ctx.notes.append(DYNAMICS_SKIPPED)
            ctx.stage = "no-dynamics"
        else:
            ctx.samples = sampling.configurations(ctx.loaded())
            ctx.stage = DYNAMICS
    if needs == MODEL:
        return ctx.robot is not None
    if needs == BALANCE:  # masses and centres of mass: an inertia tensor error moves neither
        return ctx.robot is not None and not any(blocks_balance(f) for f in ctx.out.findings)
    return ctx.stage == DYNAMICS


def _load(ctx: Context) -> None:
    """Load the Pinocchio model; parser messages become findings, a refusal `model-load`."""
    if ctx.out.has_errors(BLOCKS_MODEL):
        ctx.notes.append(MODEL_SKIPPED)
        ctx.stage = "refused"
        return
    try:
        robot = Robot.load(ctx.urdf, spec=ctx.opts.spec, strict=False)
    except ModelLoadError as exc:
        ctx.out.add("model-load", None, exc.message)
        ctx.stage = "refused"
        return
    for msg in parser_problems(robot.parser_messages):
        rule = "parser-error" if msg.lower().startswith("error") else "parser-message"
        ctx.out.add(rule, None, f"Pinocchio/urdfdom: {msg}", text=msg)
    ctx.robot = robot
    ctx.stage = MODEL
