"""The rule table of `check`: each rule's stable id, severity, title and fix hint.

Each rule has a stable id (used by `--ignore`, the JSON schema and CI
annotations), one severity and a one-line fix hint. The rules themselves live
in one module per topic beside this one and `run.py` runs them in order; this
module, `findings.py` (what a rule reports) and `options.py` (what a run is asked)
are the floor they all stand on, so they import none of them.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

ERROR = "error"
WARNING = "warning"
_MODEL = "model"  # see Rule.blocks
_BALANCE = "balance"
_DYNAMICS = "dynamics"


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


_SENSOR_RULES = [  # check/sensors.py; in _RULES before the ROS packages'
    Rule("sensor-link", ERROR, "a sensor's <gazebo reference> is not a link of the robot",
         "name one of the robot's links (Gazebo drops the sensor)"),
    Rule("sensor-rate", ERROR, "a sensor updates faster than the physics steps",
         "lower the sensor's rate to at most 1 / dt, or lower dt"),
    Rule("sensor-fov", ERROR, "empty field of view (equal scan angles, camera fov not in (0, pi))",
         "give min_angle < max_angle for several rays, a horizontal_fov in (0, pi)"),
    Rule("sensor-range", ERROR, "range_min >= range_max or near >= far: the range is empty",
         "give range_min < range_max (near < far)"),
    Rule("sensor-sees-robot", WARNING, "a lidar's rays start in the robot's collision shapes",
         "move the lidar clear of them (it sees itself) or raise range_min past them"),
]  # fmt: skip
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
    *_SENSOR_RULES,
    # ROS packages (check DIR over package.xml directories: check/ros_packages/)
    Rule(
        "ros-joint-states-twice",
        ERROR,
        "more than one publisher of /joint_states in one launch (joint_state_publisher[_gui] "
        "beside a joint_state_broadcaster spawner or Gazebo's joint-state plugin)",
        "remove the extra publisher (the message says which one stays)",
    ),
    Rule(
        "ros-control-node-with-sim",
        ERROR,
        "ros2_control_node launched for a robot whose <ros2_control> hardware is a simulator's "
        "system (gz_ros2_control, gazebo_ros2_control), which runs its own controller manager",
        "remove the ros2_control_node; spawn the controllers on the simulator's controller manager",
    ),
    Rule(
        "ros-wheel-geometry",
        ERROR,
        "diff-drive wheel separation or radius (plugin or controller YAML) more than 1 % from "
        "the URDF's wheels, or a diff_drive_controller parameter the distro no longer has",
        "write the URDF's value (in the message)",
    ),
    Rule(
        "ros-unknown-joint",
        ERROR,
        "a controller, <ros2_control> block or MoveIt YAML names a joint the URDF lacks",
        "use the URDF's joint name (the message suggests the closest)",
    ),
    Rule(
        "ros-srdf-unknown",
        ERROR,
        "an SRDF group, chain, end effector, group state, passive joint or collision entry "
        "names a joint, link or group the robot lacks",
        "use the URDF's name (the message suggests the closest)",
    ),
    Rule(
        "ros-classic-plugin",
        ERROR,
        "a Gazebo plugin the launch's simulator does not load (Gazebo classic's in Gazebo "
        "Harmonic or the reverse, or another distro's name)",
        "use the plugin of the simulator the launch starts",
    ),
    Rule(
        "ros-sim-time",
        WARNING,
        "a node of a launch that starts Gazebo without use_sim_time: true",
        "give the node use_sim_time: true (or SetParameter use_sim_time for the launch)",
    ),
    Rule(
        "ros-start-sag",
        WARNING,
        "at a named pose the arm, held by its controller's gains, settles farther from the "
        "command than MoveIt's allowed_start_tolerance or the goal tolerance: Execute fails",
        "raise p (the message gives the value that holds) or add an integral term",
    ),
    Rule(
        "ros-missing-depend",
        WARNING,
        "a launch file uses a package its package.xml does not depend on",
        "add the <exec_depend> to package.xml",
    ),
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
