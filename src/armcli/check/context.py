"""What the rule families of `check` share for one file, and the stages they need.

`run.py` builds one `Context` per URDF and hands it to each family of its registry. A
family declares the stage it needs: `URDF` (the parsed document and its tree), `MODEL`
(the Pinocchio model, loaded once and only while no error of a rule that `blocks` the
model stands), `BALANCE` (also valid masses, centres of mass and joint ranges: no negative
mass, zero axis or limits out of order) or `DYNAMICS` (also no error of a rule that blocks
the dynamics, such as an inertia tensor that is not positive definite). Families write
findings to `out`, notes to `notes`, and what later ones or the summary read (the gravity
load in `rows`, the servo joints, the PD verdict) here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

from armcli.analysis.rate import RateVerdict
from armcli.analysis.verdict import StabilityReport
from armcli.check.findings import Collector, Finding, JointRow
from armcli.check.options import CheckOptions
from armcli.check.rules import ERROR, RULES
from armcli.robot.model import Robot
from armcli.spec.joint_types import position_bounds
from armcli.urdf.doc import Urdf
from armcli.urdf.tree import KinematicTree

if TYPE_CHECKING:  # the balance and reach results: imported by their own families
    from armcli.analysis.balance import StaticBalance
    from armcli.analysis.stance import Stance
    from armcli.analysis.workspace import ReachPoint, Workspace
    from armcli.sim.tipping import ZmpReport

Stage = Literal["urdf", "model", "balance", "dynamics"]
URDF: Stage = "urdf"
MODEL: Stage = "model"
BALANCE: Stage = "balance"
DYNAMICS: Stage = "dynamics"

# Errors after which the model is not loaded (urdfdom would only repeat them: a NaN mass
# came back as two parser errors, a nameless <robot> as model-load), and after which the
# dynamics rules would compute with unusable numbers. Declared per rule in rules.py.
BLOCKS_MODEL = frozenset(r.id for r in RULES.values() if r.blocks == MODEL)
BLOCKS_BALANCE = BLOCKS_MODEL | {r.id for r in RULES.values() if r.blocks == BALANCE}
BLOCKS_DYNAMICS = BLOCKS_BALANCE | {r.id for r in RULES.values() if r.blocks == DYNAMICS}
MODEL_SKIPPED = "model checks skipped: fix the structure errors first"


def blocks_balance(f: Finding) -> bool:
    """Whether an error stops the static balance: masses, centres of mass, joint ranges.

    A moving body without mass (`mass-nonpositive` of mass 0, check/bodies.py) blocks only
    the dynamics: it moves neither the centre of mass nor the support polygon (PR2's
    massless sensor frames). A negative mass does move the centre of mass.
    """
    if f.severity != ERROR or f.rule not in BLOCKS_BALANCE:
        return False
    return not (f.rule == "mass-nonpositive" and f.values.get("mass") == 0.0)


DYNAMICS_SKIPPED = "dynamics checks skipped: fix the number and inertia errors first"


@dataclass
class Context:
    """One file under check: inputs, findings so far, and what earlier stages derived."""

    urdf: Urdf
    opts: CheckOptions
    out: Collector
    tree: KinematicTree
    notes: list[str] = field(default_factory=list)
    rows: tuple[JointRow, ...] = ()  # the joint table; the gravity rule fills its load
    robot: Robot | None = None  # the Pinocchio model and its joint table, once loaded
    samples: list[tuple[dict[str, float], Any]] = field(default_factory=list)  # dynamics
    servo: set[str] = field(default_factory=set)  # joints a position servo drives
    stability: StabilityReport | None = None
    rate: RateVerdict | None = None  # check/controller_rate.py: the ros2_control loop
    balance: StaticBalance | None = None  # check/tipover.py
    stance: Stance | None = None  # the robot on its support polygon (check/tipover.py)
    zmp: ZmpReport | None = None  # check/zmp.py: the trajectory's zero-moment point
    reach: Workspace | None = None  # check/reach.py: the tool point's envelope
    reach_points: tuple[ReachPoint, ...] = ()  # --reach-point verdicts
    stage: Stage | Literal["unloaded", "refused", "no-dynamics"] = "unloaded"

    def loaded(self) -> Robot:
        """The robot, for the families of the MODEL stage and later (run.py loads it first)."""
        if self.robot is None:
            raise RuntimeError("the model is not loaded: this family needs the MODEL stage")
        return self.robot


def joint_rows(urdf: Urdf) -> tuple[JointRow, ...]:
    """The summary's joint table: every joint that is not fixed, with its URDF numbers."""
    rows = []
    for j in urdf.joints:
        if j.type in ("fixed", ""):
            continue
        lim = j.limit
        lower, upper = position_bounds(j.type, lim) or (None, None)
        rows.append(
            JointRow(
                j.name,
                j.type,
                lower,
                upper,
                lim.effort if lim else None,
                lim.velocity if lim else None,
                j.damping,
                j.friction,
            )
        )
    return tuple(rows)


def poses(ctx: Context) -> list[tuple[str, dict[str, float]]]:
    """Named poses of the spec (or q = 0), then every joint at its lower and upper limit."""
    robot = ctx.robot
    joints = robot.joints if robot is not None else ()
    out: list[tuple[str, dict[str, float]]] = []
    spec = ctx.opts.spec
    if spec is not None and spec.poses:
        names = set(robot.names) if robot is not None else set()
        for name in spec.poses:
            out.append((name, {k: v for k, v in spec.pose(name).items() if k in names}))
    else:
        out.append(("zero", {j.name: 0.0 for j in joints}))
    if robot is None:
        return out
    limited = [j for j in robot.leaders if not j.continuous]
    if limited:
        out.append(("lower", {j.name: j.span[0] for j in limited}))
        out.append(("upper", {j.name: j.span[1] for j in limited}))
    return [(name, robot.follow(values)) for name, values in out]  # followers follow
