"""The vocabulary of `check`: the rule table, `Finding`, `Collector` and `CheckOptions`.

Each rule has a stable id (used by `--ignore`, the JSON schema and CI
annotations), one severity and a one-line fix hint. The rules themselves live
in one module per topic beside this one and `run.py` runs them in order; this
module is the floor they all stand on, so it imports none of them.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from armcli.urdf.meshes import MeshSearch
from armcli.urdf.source import lookup_for
from armcli.xacro.lines import Origin

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

ERROR = "error"
WARNING = "warning"
_MODEL = "model"  # see Rule.blocks
_BALANCE = "balance"
_DYNAMICS = "dynamics"

Value = float | int | str | list[float] | None


@dataclass(frozen=True)
class Rule:
    """One check rule: stable id (for --ignore and JSON), severity, title and fix hint.

    `blocks`: while an error of this rule stands, the rule families that need the Pinocchio
    model ("model"), valid masses, centres of mass and joint ranges ("balance": the static
    balance) or usable dynamics numbers ("dynamics") are skipped (check/context.py). An
    inertia tensor error blocks only the dynamics: it moves no centre of mass.
    """

    id: str
    severity: str
    title: str
    hint: str
    blocks: str | None = None


_RULES = [
    # structure
    Rule(
        "duplicate-name",
        ERROR,
        "link, joint or material name used twice",
        "rename one of them",
        blocks=_MODEL,
    ),
    Rule(
        "unknown-link",
        ERROR,
        "joint parent/child is not a link",
        "fix the link name",
        blocks=_MODEL,
    ),
    Rule(
        "multiple-parents",
        ERROR,
        "link is the child of several joints",
        "a link has one parent",
        blocks=_MODEL,
    ),
    Rule(
        "root-count",
        ERROR,
        "the tree must have exactly one root",
        "connect the extra roots",
        blocks=_MODEL,
    ),
    Rule(
        "disconnected",
        ERROR,
        "links not reachable from the root",
        "add the missing joints",
        blocks=_MODEL,
    ),
    Rule(
        "joint-type",
        ERROR,
        "unknown joint type",
        "use revolute, continuous, prismatic, fixed",
        blocks=_MODEL,
    ),
    Rule(
        "missing-limit",
        ERROR,
        "revolute/prismatic joint without full <limit>",
        "give lower, upper, effort and velocity",
        blocks=_MODEL,
    ),
    Rule(
        "mimic-target",
        ERROR,
        "mimic refers to an unknown joint",
        "fix the mimic joint name",
        blocks=_MODEL,
    ),
    Rule(
        "robot-name",
        ERROR,
        "<robot> without a name",
        'give the robot a name: <robot name="...">',
        blocks=_MODEL,
    ),
    Rule(
        "material-conflict",
        WARNING,
        "material redefined with another colour",
        "define each material once at top level",
    ),
    Rule(
        "material-undefined",
        ERROR,
        "material used by a visual but never given a colour or texture",
        "define it at top level with <color rgba=...> or <texture>",
    ),
    # numbers
    Rule(
        "number-syntax",
        ERROR,
        "number missing or not parsable",
        "write plain decimal numbers",
        blocks=_MODEL,
    ),
    Rule(
        "non-finite",
        ERROR,
        "NaN or infinite number",
        "replace it with a finite value",
        blocks=_MODEL,
    ),
    Rule(
        "vector-length",
        ERROR,
        "vector with the wrong number of values",
        "give 3 (rgba: 4)",
        blocks=_MODEL,
    ),
    Rule("geometry-size", ERROR, "geometry size not > 0", "give positive sizes"),
    Rule(
        "geometry-kind",
        ERROR,
        "geometry empty or of an unknown kind",
        "use box, cylinder, sphere or mesh",
    ),
    Rule("rgba-range", ERROR, "colour component outside [0, 1]", "scale colours to [0, 1]"),
    # inertia
    Rule(
        "mass-nonpositive",
        ERROR,
        "negative mass, or a moving body without mass",
        "give the link its real mass",
        blocks=_BALANCE,
    ),
    Rule(
        "inertia-not-pd",
        ERROR,
        "inertia of a link with mass not positive definite, or a moving body's singular",
        "use the solid-body formula for the link's shape",
        blocks=_DYNAMICS,
    ),
    Rule(
        "inertia-triangle",
        ERROR,
        "principal moments violate I1 + I2 >= I3",
        "a real body has I1 + I2 >= I3; recompute the inertia",
        blocks=_DYNAMICS,
    ),
    Rule(
        "tiny-mass",
        WARNING,
        "mass tiny compared with the robot",
        "simulators become stiff with mass ratios above 1e4; use a realistic mass",
    ),
    Rule(
        "missing-inertial",
        WARNING,
        "moving link with geometry but no <inertial>",
        "add an <inertial>; Gazebo drops links without one",
    ),
    Rule(
        "root-inertia",
        WARNING,
        "root link has an inertia (KDL ignores it)",
        "add a massless dummy root link, e.g. base_footprint",
    ),
    Rule(
        "inertia-exceeds-geometry",
        ERROR,
        "a moment of inertia above what any mass inside the link's one primitive can have",
        "write the inertia of the shape and mass (the value in the message)",
    ),
    Rule(
        "inertia-exceeds-visual",
        WARNING,
        "a moment of inertia above what any mass inside the link's one visual-only primitive "
        "can have",
        "a visual without a collision may be only illustrative (Go1's rotors); if it is the "
        "body, write the inertia of the shape and mass (the value in the message)",
    ),
    Rule(
        "inertia-geometry",
        WARNING,
        "inertia differs from the solid-body formula of the geometry",
        "compute it from the shape (armcli's box/cylinder/sphere formulas)",
    ),
    Rule(
        "com-geometry",
        WARNING,
        "inertial origin is not at the geometry centre",
        "put the inertial origin at the shape's centre",
    ),
    # joints
    Rule(
        "limit-order",
        ERROR,
        "lower limit not below upper limit",
        "swap or fix the limits",
        blocks=_BALANCE,
    ),
    Rule(
        "limit-effort-velocity",
        ERROR,
        "effort or velocity limit <= 0",
        "give the actuator's real effort and velocity limits",
    ),
    Rule("axis", ERROR, "joint axis zero", "give a unit axis such as 0 0 1", blocks=_BALANCE),
    Rule("axis-unit", WARNING, "joint axis not unit length", "normalise the axis"),
    Rule(
        "limit-degrees",
        WARNING,
        "revolute limit a round number beyond 2*pi: degrees, not radians?",
        "URDF angles are radians",
    ),
    Rule("spec-limits", ERROR, "joint limits differ from the spec", "rebuild from the spec"),
    # model and dynamics
    Rule("parser-error", ERROR, "the URDF parser reported an error", "read the message"),
    Rule("parser-message", WARNING, "the URDF parser printed a message", "read the message"),
    Rule("model-load", ERROR, "Pinocchio cannot build a model", "fix the errors above"),
    Rule(
        "gravity-effort",
        ERROR,
        "gravity torque exceeds the effort limit",
        "raise the effort limit or lighten the links",
    ),
    Rule(
        "pd-unstable",
        ERROR,
        "PD loop unstable at dt in armcli simulate (damping implicit); gravity's stiffness counts",
        "lower dt or Kp (`armcli tune` picks stable gains)",
    ),
    Rule(
        "pd-explicit-unstable",
        WARNING,
        "PD loop unstable at dt in an explicit torque loop (ros2_control effort controller)",
        "lower dt or Kd (`armcli tune --loop explicit` picks gains for this loop)",
    ),
    Rule(
        "servo-unstable",
        ERROR,
        "gz_ros2_control position servo diverges: position_proportional_gain not in (0, 2)",
        "set <position_proportional_gain> in the gz_ros2_control plugin below 1",
    ),
    Rule(
        "servo-oscillates",
        WARNING,
        "gz_ros2_control position servo overshoots: position_proportional_gain in (1, 2)",
        "set <position_proportional_gain> to at most 1",
    ),
    # collision and meshes
    Rule(
        "visual-no-collision",
        WARNING,
        "moving link with visual but no collision geometry",
        "add a <collision> (a primitive is enough)",
    ),
    Rule(
        "self-collision", ERROR, "links collide at a named pose", "change the pose or the geometry"
    ),
    Rule("mesh-missing", ERROR, "mesh file not found", "fix the path or pass --package-dir"),
    # balance and reach (check/tipover.py, check/zmp.py, check/reach.py)
    Rule(
        "com-outside-support",
        ERROR,
        "centre of mass outside the support polygon at a pose or somewhere in the joint range",
        "lighten the payload (the message says how much holds), keep out of that pose, "
        "or widen the base",
    ),
    Rule(
        "support-margin",
        WARNING,
        "centre of mass closer to the support polygon's edge than the threshold",
        "lighten the payload or keep the arm closer to the base's centre",
    ),
    Rule(
        "zmp-outside-support",
        ERROR,
        "zero-moment point leaves the support polygon along --trajectory: the robot tips",
        "slow the arm down or lower the base's acceleration (the message says how much holds)",
    ),
    Rule(
        "zmp-margin",
        WARNING,
        "zero-moment point closer to the support polygon's edge than the threshold",
        "slow the arm down or lower the base's acceleration",
    ),
    Rule(
        "reach-point",
        ERROR,
        "a --reach-point the tool point cannot reach within the joint limits",
        "move the point or the arm's mount (the message says how close the arm gets)",
    ),
    # inputs
    Rule(
        "input-unusable",
        ERROR,
        "file could not be read as a URDF (not XML, not URDF, refused, too large)",
        "fix or remove the file",
    ),
]
RULES: dict[str, Rule] = {r.id: r for r in _RULES}


def unknown_rules(ids: Iterable[str]) -> list[str]:
    """The ids among `ids` that name no rule, sorted (for `--ignore`)."""
    return sorted(set(ids) - set(RULES))


@dataclass(frozen=True)
class SpecPlace:
    """Where in a spec file a finding in its generated URDF comes from (check.spec_locate)."""

    file: str
    line: int | None
    field: str  # dotted field path, e.g. arm.joints.forearm_hand_joint.limit.upper

    def __str__(self) -> str:
        return f"{self.file}:{self.line} {self.field}" if self.line else f"{self.file} {self.field}"


@dataclass(frozen=True)
class Finding:
    """One problem: which rule, where, what the numbers are, and how to fix it."""

    rule: str
    severity: str
    file: str
    line: int | None
    message: str
    values: Mapping[str, Value] = field(default_factory=dict)
    hint: str = ""
    fix: Mapping[str, Value] = field(default_factory=dict)  # the numbers that would pass
    spec: SpecPlace | None = None  # the spec field behind a generated URDF's element
    origin: Origin | None = None  # a xacro expansion's element: the line the user wrote

    @property
    def calls_text(self) -> str:
        """The `(through the macro call at FILE:LINE, ...)` suffix of a macro's element."""
        if self.origin is None or not self.origin.calls:
            return ""
        at = ", then ".join(f"{shown_path(f)}:{n}" for f, n in self.origin.calls)
        return f" (through the macro call at {at})"

    def to_dict(self) -> dict[str, Any]:
        """The finding as a JSON object in the stable schema of docs/check.md."""
        return {
            "rule": self.rule,
            "severity": self.severity,
            "file": self.file,
            "line": self.line,
            "message": self.message,
            "values": dict(self.values),
            "hint": self.hint,
            "fix": dict(self.fix),
            "spec": None if self.spec is None else vars(self.spec).copy(),
            "origin": None
            if self.origin is None
            else {
                "file": self.origin.file,
                "line": self.origin.line,
                "calls": [{"file": f, "line": n} for f, n in self.origin.calls],
            },
        }


def shown_path(path: str) -> str:
    """A path as a message shows it: relative to the working directory when under it."""
    rel = os.path.relpath(path) if os.path.isabs(path) else path
    return path if rel.startswith("..") else rel


class Collector:
    """Builds findings for one file, filling severity and hint from the rule table."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.findings: list[Finding] = []

    def add(
        self,
        rule: str,
        line: int | None,
        message: str,
        fix: Mapping[str, Value] | None = None,
        /,
        **values: Value,
    ) -> None:
        """Record a finding of `rule` at `line`.

        `values` are the numbers behind the message, `fix` the numeric remedy (e.g. the
        inertia that would pass); `fix` is positional-only so no value can shadow it.
        """
        r = RULES[rule]
        self.findings.append(
            Finding(rule, r.severity, self.file, line, message, values, r.hint, dict(fix or {}))
        )

    def has(self, rules: Iterable[str], **values: Value) -> bool:
        """True when a finding of one of `rules` already carries these values (one per problem)."""
        wanted = set(rules)
        return any(
            f.rule in wanted and all(f.values.get(k) == v for k, v in values.items())
            for f in self.findings
        )

    def has_errors(self, rules: Iterable[str] | None = None) -> bool:
        """Whether an error-severity finding was recorded, optionally only among `rules`."""
        wanted = set(rules) if rules is not None else None
        return any(
            f.severity == ERROR and (wanted is None or f.rule in wanted) for f in self.findings
        )


@dataclass(frozen=True)
class JointRow:
    """One joint of the summary table: URDF limits and dynamics [SI], and the gravity load."""

    name: str
    type: str
    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    damping: float
    friction: float
    gravity_max: float | None = None  # worst |gravity torque| over the sample [N·m or N]


@dataclass(frozen=True)
class TipoverOptions:
    """Balance and reach options (check/tipover.py, check/zmp.py, check/reach.py)."""

    payload: float = 0.0  # [kg] point mass at the payload point
    payload_link: str | None = None  # its link (at the origin); default: the tool point
    contact_links: tuple[str, ...] | None = None  # default: found from the geometry
    min_margin: float = 0.02  # [m] margin below which `support-margin` warns
    trajectory: Path | None = None  # simulate it and report the zero-moment point
    base_accel: float | None = None  # [m/s²] default: the diff-drive plugin's
    reach_points: tuple[tuple[float, float, float], ...] = ()  # [m] in the root frame


@dataclass(frozen=True)
class CheckOptions:
    """What the rules may use beyond the URDF itself."""

    spec: RobotSpec | None = None
    package_dirs: Mapping[str, Path] = field(default_factory=dict)
    search_paths: tuple[Path, ...] = ()
    tipover: TipoverOptions = field(default_factory=TipoverOptions)

    def mesh_search(self) -> MeshSearch:
        """The mesh-resolver view of these options (shared with view and render)."""
        return lookup_for(self.spec, MeshSearch(self.package_dirs, self.search_paths))


def apply_policy(
    findings: Iterable[Finding], *, ignore: Iterable[str] = (), strict: bool = False
) -> list[Finding]:
    """Drop ignored rules; with strict, every warning becomes an error."""
    skip = set(ignore)
    out = []
    for f in findings:
        if f.rule in skip:
            continue
        if strict and f.severity == WARNING:
            f = replace(f, severity=ERROR)
        out.append(f)
    return out
