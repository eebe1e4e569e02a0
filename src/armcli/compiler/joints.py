"""Spec joints -> URDF `<joint>` elements (the one writer for every part and the mount)."""

from __future__ import annotations

from lxml import etree

from armcli.compiler.passthrough import copy_into
from armcli.compiler.xmlfmt import fmt, sub, vec
from armcli.spec.joint_types import AXIS_TYPES
from armcli.spec.model import Joint


def _limit(el: etree._Element, joint: Joint) -> None:
    lim = joint.limit
    if lim is None:
        return
    attrs = {}
    if lim.lower is not None:
        attrs["lower"] = fmt(lim.lower)
    if lim.upper is not None:
        attrs["upper"] = fmt(lim.upper)
    attrs.update(effort=fmt(lim.effort), velocity=fmt(lim.velocity))
    if lim.acceleration is not None:  # URDF 1.2; written only when the spec gives it
        attrs["acceleration"] = fmt(lim.acceleration)
    sub(el, "limit", **attrs)


def joint_element(parent: etree._Element, name: str, joint: Joint) -> etree._Element:
    """Append the URDF `<joint>` of `joint` to `parent` and return it.

    Fixed and floating joints get no axis; everything else is written as the spec
    gives it, in SI units (a continuous joint has position bounds only if given).
    """
    el = sub(parent, "joint", name=name, type=joint.type)
    sub(el, "parent", link=joint.parent)
    sub(el, "child", link=joint.child)
    sub(el, "origin", xyz=vec(joint.origin.xyz), rpy=vec(joint.origin.rpy))
    if joint.type in AXIS_TYPES:
        sub(el, "axis", xyz=vec(joint.axis))
    _limit(el, joint)
    if joint.dynamics is not None:
        sub(
            el,
            "dynamics",
            friction=fmt(joint.dynamics.friction),
            damping=fmt(joint.dynamics.damping),
        )
    if joint.mimic is not None:
        m = joint.mimic
        sub(el, "mimic", joint=m.joint, multiplier=fmt(m.multiplier), offset=fmt(m.offset))
    if joint.safety_controller is not None:
        s = joint.safety_controller
        sub(
            el,
            "safety_controller",
            soft_lower_limit=fmt(s.soft_lower_limit),
            soft_upper_limit=fmt(s.soft_upper_limit),
            k_position=fmt(s.k_position),
            k_velocity=fmt(s.k_velocity),
        )
    if joint.calibration is not None:
        c = joint.calibration
        attrs = {
            k: fmt(v) for k, v in (("rising", c.rising), ("falling", c.falling)) if v is not None
        }
        sub(el, "calibration", **attrs)
    copy_into(el, joint.passthrough)
    return el
