"""Issue 28's "each robot fact built once", checked on the source.

One kinematic-tree type (urdf/tree.py) that check builds on; the URDF's mimic joints and
simulator extensions read once, into the typed document (urdf/read.py, urdf/extensions.py);
one time-step rule (spec/types.py's `time_step`).
"""

from __future__ import annotations

import ast
import re
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


EXTENSION_READ = re.compile(
    r"\.(find|findall|findtext|iter|iterfind|xpath)\(\s*[\"'][^\"']*"
    r"\b(mimic|gazebo|ros2_control|plugin|transmission)\b"
)
READERS = ("urdf/read.py", "urdf/extensions.py")  # the one reading, into urdf/doc.py's types
NOT_CONSUMERS = {
    "importer/": "transcribes every element of a foreign URDF into a spec, unknown ones verbatim",
    "compiler/": "walks the xacro it writes itself",
}


def test_extensions_are_read_once() -> None:
    """check/interface.py, check/joints.py, export/mjcf_report.py and drive/model.py each
    parsed `<ros2_control>`, `<transmission>`, `<gazebo>` or `<mimic>` again with lxml."""
    found = [
        f"{rel}:{i}: {line.strip()}"
        for p in sorted(SRC.rglob("*.py"))
        if not (rel := p.relative_to(SRC).as_posix()).startswith((*READERS, *NOT_CONSUMERS))
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if EXTENSION_READ.search(line)
    ]
    assert not found, "read them from the typed `Urdf` (urdf/doc.py):\n" + "\n".join(found)


DT_TEST = re.compile(  # isfinite(dt), 0 < dt, dt > 0, dt <= 0 on anything named dt
    r"isfinite\([^)]*\bdt\b|\b0(\.0)?\s*<\s*[\w.]*\bdt\b|\bdt\s*(>|<=)\s*0(\.0)?\b"
)


def test_the_time_step_is_validated_by_one_rule() -> None:
    """sim/simulate.py (finite, > 0) and sim/job.py (in (0, 0.1]) each had a rule of their
    own, and the spec a third (> 0); tests/cli/test_flags.py checks each entry uses this one."""
    found = [
        f"{rel}:{i}: {line.strip()}"
        for p in sorted(SRC.rglob("*.py"))
        if (rel := p.relative_to(SRC).as_posix()) != "spec/types.py"
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if DT_TEST.search(line)
    ]
    assert not found, "call armcli.spec.types.time_step:\n" + "\n".join(found)
