"""What a URDF says that MJCF cannot, and what the MJCF export did with it.

URDF carries simulator-specific extras (`<gazebo>`, `<transmission>`,
`<ros2_control>`) and limits MuJoCo has no field for (joint velocity). The
export never drops anything silently: every such item becomes a `Note` in the
report, printed by `armcli export mjcf` and kept beside the model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from armcli.robot.mimic import Mimic
from armcli.urdf.doc import Urdf

EXTRA_TAGS = ("gazebo", "transmission", "ros2_control")


@dataclass(frozen=True)
class Note:
    """One thing MuJoCo cannot represent as URDF does, and what was done instead."""

    topic: str  # e.g. "velocity limits"
    what: str  # what the URDF says
    done: str  # what the export did


@dataclass(frozen=True)
class Extras:
    """What the export needs of the URDF's mimic joints and simulator extensions."""

    mimic: dict[str, Mimic] = field(default_factory=dict)  # follower -> its coupling
    mu1: dict[str, float] = field(default_factory=dict)  # link -> Gazebo friction coefficient
    tags: dict[str, int] = field(default_factory=dict)  # extra tag -> count


def _float(text: str | None, default: float) -> float:
    try:
        return float(text) if text else default
    except ValueError:
        return default


def scan(urdf: Urdf) -> Extras:
    """Mimic parameters, Gazebo `mu1` per link and the counts of simulator-specific tags."""
    mimic = {
        j.name: Mimic(j.name, j.mimic, j.mimic_multiplier, j.mimic_offset)
        for j in urdf.joints
        if j.mimic
    }
    mu1 = {
        g.reference: _float(g.values["mu1"], 1.0)
        for g in urdf.gazebo
        if g.reference and "mu1" in g.values
    }
    counts = {
        "gazebo": len(urdf.gazebo),
        "transmission": len(urdf.transmissions),
        "ros2_control": len(urdf.ros2_control),
    }
    tags = {t: n for t in EXTRA_TAGS if (n := counts[t])}
    return Extras(mimic, mu1, tags)


def text(notes: list[Note] | tuple[Note, ...]) -> str:
    """The report as plain text, one block per note."""
    if not notes:
        return "MuJoCo represents everything in this URDF.\n"
    out = ["What MuJoCo cannot represent, and what was done:"]
    for n in notes:
        out.append(f"- {n.topic}: {n.what}")
        out.append(f"  -> {n.done}")
    return "\n".join(out) + "\n"
