"""The layer rules of docs/ARCHITECTURE.md, checked on the real import graph of src/armcli.

Every armcli-internal import (at module top or inside a function) must point to the
same subpackage or a lower layer; siblings only through the documented exceptions; and
the module graph has no cycles.
"""

from __future__ import annotations

import ast
from pathlib import Path

from tests.helpers import ROOT

SRC = ROOT / "src" / "armcli"
RANK = {  # layer of each top-level module or subpackage (docs/ARCHITECTURE.md)
    "errors": 0, "defaults": 0, "compiled": 0, "io": 1, "spec": 2, "xacro": 3, "compiler": 4,
    "urdf": 5, "robot": 6, "analysis": 7, "trajectory": 8, "export": 9, "importer": 9, "ros": 9,
    "sim": 10, "drive": 11, "check": 12, "tune": 12, "plan": 12, "view": 13, "commands": 14,
    "cli": 15, "__main__": 16,
}  # fmt: skip


def _module_name(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("armcli"):
            for alias in node.names:
                full = f"{node.module}.{alias.name}"  # `from armcli.analysis import stability`
                as_path = SRC.parent / full.replace(".", "/")
                is_module = as_path.with_suffix(".py").exists() or as_path.is_dir()
                out.add(full if is_module else node.module)
        elif isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("armcli")}
    return out


def _graph() -> dict[str, set[str]]:
    return {_module_name(p): _imports(p) for p in SRC.rglob("*.py")}


def _layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "errors"  # the package itself holds only metadata


def test_every_layer_is_documented() -> None:
    doc = (ROOT / "docs" / "ARCHITECTURE.md").read_text()
    for entry in SRC.iterdir():
        name = entry.stem if entry.suffix == ".py" else entry.name
        if entry.name.startswith("_") or entry.name in ("data", "examples", "py.typed"):
            continue
        assert name in RANK, f"{name}: add it to RANK and docs/ARCHITECTURE.md"
        assert f"`{name}`" in doc or f"{name}/" in doc or f"{name}.py" in doc, name


def test_imports_only_go_down() -> None:
    bad = []
    for module, targets in _graph().items():
        here = _layer(module)
        for target in targets:
            there = _layer(target)
            if target == "armcli" or here == there:
                continue
            if RANK[there] > RANK[here]:
                bad.append(f"{module} -> {target} (upward)")
            elif RANK[there] == RANK[here]:
                bad.append(f"{module} -> {target} (sibling)")
    assert not bad, "\n".join(sorted(bad))


def test_no_import_cycles() -> None:
    graph = _graph()
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph.get(node, ())):
            if nxt not in graph:
                continue
            if state.get(nxt) == 1:
                raise AssertionError("cycle: " + " -> ".join([*stack, node, nxt]))
            if nxt not in state:
                visit(nxt, [*stack, node])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])


MAX_MODULE_LINES = 400  # issue 28: one concept per module; past this a module holds two


def test_no_module_is_over_the_line_budget() -> None:
    long = {
        str(p.relative_to(SRC)): n
        for p in SRC.rglob("*.py")
        if (n := len(p.read_text().splitlines())) > MAX_MODULE_LINES
    }
    assert not long, long
