"""Issue 28's "each robot fact built once", checked on the source.

One kinematic-tree type (urdf/tree.py) that check builds on.
"""

from __future__ import annotations

import ast
from pathlib import Path

from tests.helpers import ROOT

SRC = ROOT / "src" / "armcli"
TREE_FIELDS = ("parent_joint", "roots", "orphans", "extra_parents")  # what makes a tree type


def _classes() -> list[tuple[str, ast.ClassDef]]:
    return [
        (p.relative_to(SRC).as_posix(), node)
        for p in sorted(SRC.rglob("*.py"))
        for node in ast.walk(ast.parse(p.read_text()))
        if isinstance(node, ast.ClassDef)
    ]


def _fields(cls: ast.ClassDef) -> set[str]:
    return {
        n.target.id
        for n in cls.body
        if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)
    }


def test_one_kinematic_tree_type() -> None:
    """check/structure.py once had its own `Tree` beside urdf/tree.py's `KinematicTree`."""
    named = {f"{path}:{c.name}" for path, c in _classes() if "Tree" in c.name}
    assert named == {"urdf/tree.py:KinematicTree", "urdf/tree.py:TreeView"}
    shaped = {f"{path}:{c.name}" for path, c in _classes() if _fields(c) & set(TREE_FIELDS)}
    assert shaped == {"urdf/tree.py:KinematicTree"}


def test_check_builds_on_the_tree_type() -> None:
    from armcli.check import structure
    from armcli.check.context import Context

    assert structure.check.__annotations__["return"] == "KinematicTree"
    assert Context.__annotations__["tree"] == "KinematicTree"
    assert "class Tree" not in Path(structure.__file__).read_text()
