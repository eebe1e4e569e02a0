"""The one root-link rule, shared by spec validation, the URDF tree, check and the writers."""

from __future__ import annotations

from collections.abc import Iterable


def root_links(links: Iterable[str], child_links: Iterable[str]) -> list[str]:
    """Links that are no joint's child, in the given link order (a tree has exactly one)."""
    children = set(child_links)
    return [name for name in links if name not in children]
