"""The rule table of `check`: each rule's stable id, severity, title and fix hint.

Each rule has a stable id (used by `--ignore`, the JSON schema and CI
annotations), one severity and a one-line fix hint. The rules themselves live
in one module per topic beside this one and `run.py` runs them in order; this
module (with `rule.py`, the `Rule` record, and `ros_rules.py`, the package rules' table),
`findings.py` (what a rule reports) and `options.py` (what a run is asked) are the floor
they all stand on, so they import none of them.
"""

from __future__ import annotations

from collections.abc import Iterable

from armcli.check.ros_rules import ROS_RULES
from armcli.check.rule import ERROR, WARNING, Rule

__all__ = ["ERROR", "RULES", "WARNING", "Rule", "unknown_rules"]

_MODEL = "model"  # see Rule.blocks
_BALANCE = "balance"
_DYNAMICS = "dynamics"


_SENSOR_RULES = [  # check/sensors.py; in _RULES before the ROS packages'
    Rule(
        "sensor-link",
        ERROR,
        "a sensor's <gazebo reference> is not a link of the robot",
        "name one of the robot's links (Gazebo drops the sensor)",
    ),
    Rule(
        "sensor-rate",
        ERROR,
        "a sensor updates faster than the physics steps",
        "lower the sensor's rate to at most 1 / dt, or lower dt",
    ),
    Rule(
        "sensor-fov",
        ERROR,
        "empty field of view (equal scan angles, camera fov not in (0, pi))",
        "give min_angle < max_angle for several rays, a horizontal_fov in (0, pi)",
    ),
    Rule(
        "sensor-range",
        ERROR,
        "range_min >= range_max or near >= far: the range is empty",
        "give range_min < range_max (near < far)",
    ),
    Rule(
        "sensor-sees-robot",
        WARNING,
        "a lidar's rays start in the robot's collision shapes",
        "move the lidar clear of them (it sees itself) or raise range_min past them",
    ),
]
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
        "PD loop unstable at dt in an explicit torque loop (a torque controller updated every dt)",
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
    *_SENSOR_RULES,
    *ROS_RULES,
    # inputs
    Rule(
        "input-unusable",
        ERROR,
        "file could not be read (a URDF, launch file, YAML or package.xml: malformed, refused, "
        "too large)",
        "fix or remove the file",
    ),
]
RULES: dict[str, Rule] = {r.id: r for r in _RULES}


def unknown_rules(ids: Iterable[str]) -> list[str]:
    """The ids among `ids` that name no rule, sorted (for `--ignore`)."""
    return sorted(set(ids) - set(RULES))
