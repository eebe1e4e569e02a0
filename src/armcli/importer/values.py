"""Numbers and poses read from URDF elements for the import, refusing what is not finite."""

from __future__ import annotations

import math
from typing import Any

from lxml import etree

from armcli.errors import InputError
from armcli.importer.yamltext import Num


class Reader:
    """Reads numbers from one URDF document; a bad number is an InputError with its line."""

    def __init__(self, source: str) -> None:
        self.source = source

    def floats(
        self, el: etree._Element, attr: str, n: int, default: tuple[float, ...] | None = None
    ) -> tuple[float, ...] | None:
        """The `n` numbers of `el`'s attribute `attr` (`default` if absent)."""
        raw = el.get(attr)
        if raw is None:
            return default
        try:
            vals = tuple(float(x) for x in raw.split())
        except ValueError:
            vals = ()
        if len(vals) != n or not all(math.isfinite(v) for v in vals):
            raise InputError(
                f"<{el.tag} {attr}={raw!r}>: expected {n} finite number(s)",
                file=self.source,
                line=el.sourceline if isinstance(el.sourceline, int) else None,
            )
        return vals

    def one(self, el: etree._Element, attr: str, default: float | None = None) -> float | None:
        """One number of `el`'s attribute `attr` (`default` if absent)."""
        got = self.floats(el, attr, 1, None)
        return got[0] if got is not None else default

    def pose(self, el: etree._Element) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(xyz, rpy) of `el`'s `<origin>`; zeros where absent."""
        origin = el.find("origin")
        if origin is None:
            return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        xyz = self.floats(origin, "xyz", 3, (0.0, 0.0, 0.0))
        rpy = self.floats(origin, "rpy", 3, (0.0, 0.0, 0.0))
        assert xyz is not None and rpy is not None
        return xyz, rpy


def nums(values: tuple[float, ...] | list[float]) -> list[Num]:
    """Values as exact YAML numbers."""
    return [Num(v) for v in values]


def origin_data(xyz: tuple[float, ...], rpy: tuple[float, ...]) -> dict[str, Any] | None:
    """The spec's `origin` mapping, leaving out zero parts; None for the identity."""
    out: dict[str, Any] = {}
    if any(xyz):
        out["xyz"] = nums(xyz)
    if any(rpy):
        out["rpy"] = nums(rpy)
    return out or None


def xml_text(el: etree._Element) -> str:
    """An element as indented XML text without its tail, for `passthrough`.

    The tail (stray text after the element, as in some students' URDFs) is left out
    before re-parsing: with it the text is not one XML document.
    """
    copy = etree.fromstring(etree.tostring(el, with_tail=False))
    etree.indent(copy, space="  ")
    return etree.tostring(copy, encoding="unicode")
