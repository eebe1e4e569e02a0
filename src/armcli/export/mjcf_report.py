"""What a URDF says that MJCF cannot, and what the MJCF export did with it.

URDF carries simulator-specific extras (`<gazebo>`, `<transmission>`,
`<ros2_control>`) and limits MuJoCo has no field for (joint velocity). The
export never drops anything silently: every such item becomes a `Note` in the
report, printed by `armcli export mjcf` and kept beside the model.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lxml import etree

EXTRA_TAGS = ("gazebo", "transmission", "ros2_control")


@dataclass(frozen=True)
class Note:
    """One thing MuJoCo cannot represent as URDF does, and what was done instead."""

    topic: str  # e.g. "velocity limits"
    what: str  # what the URDF says
    done: str  # what the export did


@dataclass(frozen=True)
class Mimic:
    """`<mimic joint= multiplier= offset=>`: q = multiplier * q_joint + offset."""

    joint: str
    multiplier: float
    offset: float


@dataclass(frozen=True)
class Extras:
    """URDF content outside urdfdoc's typed view that the export needs."""

    mimic: dict[str, Mimic] = field(default_factory=dict)  # follower -> leader
    mu1: dict[str, float] = field(default_factory=dict)  # link -> Gazebo friction coefficient
    tags: dict[str, int] = field(default_factory=dict)  # extra tag -> count


def _float(text: str | None, default: float) -> float:
    try:
        return float(text) if text is not None else default
    except ValueError:
        return default


def _mu1(el: etree._Element) -> float | None:
    mu = el.find("mu1")
    if mu is None:
        return None
    return _float(mu.get("value", mu.text), 1.0)


def scan(root: etree._Element) -> Extras:
    """Mimic parameters, Gazebo `mu1` per link and the counts of simulator-specific tags."""
    mimic = {}
    for j in root.findall("joint"):
        m = j.find("mimic")
        if m is not None and m.get("joint"):
            mimic[j.get("name", "")] = Mimic(
                str(m.get("joint")), _float(m.get("multiplier"), 1.0), _float(m.get("offset"), 0.0)
            )
    mu1 = {}
    for g in root.findall("gazebo"):
        value = _mu1(g)
        if g.get("reference") and value is not None:
            mu1[str(g.get("reference"))] = value
    tags = {t: n for t in EXTRA_TAGS if (n := len(root.findall(t)))}
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
