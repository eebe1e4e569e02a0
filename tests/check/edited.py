"""The course's my_robot.urdf, edited in memory and checked: one rule's trigger at a time."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lxml import etree

from armcli.check.findings import Finding
from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.urdf.read import parse_urdf
from tests.helpers import ROOT

BASE = (ROOT / "urdf" / "my_robot.urdf").read_bytes()


def findings(edit: Callable[[Any], None], spec: Any = None) -> list[Finding]:
    """The findings of BASE after `edit(root)` (with the spec's options when given)."""
    root = etree.fromstring(BASE)
    edit(root)
    data = etree.tostring(root, xml_declaration=True, encoding="utf-8")
    return list(check_urdf(parse_urdf(data, "x.urdf"), CheckOptions(spec=spec)).findings)


def joint(r: Any, name: str = "forearm_hand_joint") -> Any:
    """The `<joint>` element called `name`."""
    return r.find(f"joint[@name='{name}']")
