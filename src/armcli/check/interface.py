"""Which loop the URDF's `<ros2_control>` block closes, and its stability bound.

An **effort** command interface is the PD torque loop that `armcli.check.dynamics`
bounds. A **position** command interface on gz_ros2_control is not a PD loop at
all: every controller update, GazeboSimSystem::write() sets the joint velocity to

    v = position_proportional_gain * (q_cmd - q) * update_rate

and holds it for one control period T = 1/update_rate, so the error obeys
e[k+1] = (1 - gain) e[k]. That first-order servo is stable only for 0 < gain < 2
and approaches without overshoot for gain <= 1; the spec's Kp/Kd are not used.
The gain is the plugin's `<position_proportional_gain>` element, 0.1 by default
(gz_ros2_control's plugin source).
"""

from __future__ import annotations

from dataclasses import dataclass

from armcli.check.findings import Collector, Value
from armcli.check.options import CheckOptions
from armcli.urdf.doc import Plugin, Urdf

GZ_SYSTEMS = ("gz_ros2_control/GazeboSimSystem", "ign_ros2_control/IgnitionSystem")
GZ_PLUGIN_FILES = ("gz_ros2_control-system", "ign_ros2_control-system")
DEFAULT_GAIN = 0.1  # gz_ros2_control's default position_proportional_gain
STABLE_BELOW = 2.0  # |1 - gain| < 1
MONOTONE_UP_TO = 1.0  # 1 - gain >= 0


@dataclass(frozen=True)
class Interfaces:
    """The `<ros2_control>` blocks of one URDF, reduced to what the check needs."""

    hardware: tuple[str, ...]  # hardware plugins named
    command: dict[str, tuple[str, ...]]  # joint -> command interface names
    gain: float  # position_proportional_gain of the gz plugin
    line: int | None  # of the first <ros2_control>

    @property
    def gazebo(self) -> bool:
        """Whether gz_ros2_control (or its Ignition predecessor) runs the block."""
        return any(h in GZ_SYSTEMS for h in self.hardware)

    def position_joints(self) -> list[str]:
        """Joints with a position command interface (the servo law applies to them)."""
        return [j for j, names in self.command.items() if "position" in names]


def _gain(plugins: tuple[Plugin, ...]) -> float:
    for plugin in plugins:
        if plugin.filename in GZ_PLUGIN_FILES:
            text = plugin.params.get("position_proportional_gain")
            if text is not None:
                try:
                    return float(text)
                except ValueError:
                    return DEFAULT_GAIN
    return DEFAULT_GAIN


def read_interfaces(urdf: Urdf) -> Interfaces | None:
    """The `<ros2_control>` blocks, reduced; None when the URDF has none."""
    blocks = urdf.ros2_control
    if not blocks:
        return None
    command = {j: names for b in blocks for j, names in b.commands.items()}
    hardware = tuple(b.hardware for b in blocks)
    return Interfaces(hardware, command, _gain(urdf.plugins), blocks[0].line)


def check(urdf: Urdf, opts: CheckOptions, out: Collector, notes: list[str]) -> set[str]:
    """Report the servo bound for position-commanded gz joints; return those joints.

    The caller skips the PD bound when every controlled joint is among them.
    """
    ifaces = read_interfaces(urdf)
    if ifaces is None or not ifaces.gazebo:
        return set()
    joints = ifaces.position_joints()
    if not joints:
        return set()
    g = ifaces.gain
    rate = opts.spec.control.controller_update_rate if opts.spec is not None else None
    per_s = f"{g * rate:.4g}/s" if rate is not None else "gain x update_rate"
    values: dict[str, Value] = {"gain": g, "factor": 1.0 - g, "joints": ", ".join(joints)}
    where = f"gz_ros2_control position interface on {', '.join(joints)}"
    if not 0.0 < g < STABLE_BELOW:
        out.add(
            "servo-unstable",
            ifaces.line,
            f"{where}: position_proportional_gain {g:g} makes the error grow by |1 - gain| = "
            f"{abs(1 - g):.3g} per control period; stable only for 0 < gain < 2",
            **values,
        )
    elif g > MONOTONE_UP_TO:
        out.add(
            "servo-oscillates",
            ifaces.line,
            f"{where}: position_proportional_gain {g:g} overshoots, the error changes sign "
            f"every control period (factor {1 - g:.3g}); no oscillation for gain <= 1",
            **values,
        )
    notes.append(
        f"{where}: first-order servo, joint velocity = {g:g} x error x update rate "
        f"({per_s}); the error shrinks by a factor {1 - g:.3g} per control period "
        "(stable for gain < 2, no oscillation for gain <= 1); the PD bound does not apply "
        "and the spec's Kp/Kd are not used"
    )
    return set(joints)
