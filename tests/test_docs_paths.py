"""Every module the docs name exists: docs/*.md, README.md and the source's docstrings.

Names are dotted (`armcli.analysis.stability`, maybe ending in an attribute such as
`armcli.check.rules.RULES`) or paths (`sim/states.py`, relative to the repository,
`src/armcli/`, `tests/` or `bench/`). In the source's docstrings and comments, a name
relative to the package in backticks or parentheses (`(`urdf.tree`)`, `(sim.rollout: ...`)
is checked too. A renamed module fails this test until the text that sends readers to it
is updated.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from pathlib import Path

import pytest

from tests.helpers import ROOT

SRC = ROOT / "src"
DOCS = [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]
DOTTED = re.compile(r"(?<![\w.])armcli(?:\.[A-Za-z_]\w*)+")
PATH = re.compile(r"(?<![\w./-])(?:[\w-]+/)+\w+\.py\b")
PATH_ROOTS = (ROOT, SRC / "armcli", ROOT / "tests", ROOT / "bench")
FILE_SUFFIXES = {"yaml", "sarif", "json", "md", "toml", "csv", "png"}  # armcli.yaml is a file


def _module_file(parts: list[str]) -> Path | None:
    base = SRC.joinpath(*parts)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _compiled(name: str) -> bool:
    """A compiled extension (built into the install, not the source tree) of CMakeLists.txt."""
    return name.startswith("_") and name in (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")


def _defines(module: Path, name: str) -> bool:
    if name.startswith("__") or _compiled(name):  # module dunders; a compiled submodule
        return True
    text = module.read_text(encoding="utf-8")
    pattern = rf"^(?:def |class |async def )?{re.escape(name)}\b|^\s*(?:from|import) .*\b{name}\b"
    return re.search(pattern, text, re.M) is not None


def dotted_problem(name: str) -> str | None:
    """Why `name` is not a module (or a module's attribute), or None when it is."""
    parts = name.split(".")
    if parts[-1] in FILE_SUFFIXES:
        return None
    k = next(k for k in range(len(parts), 0, -1) if _module_file(parts[:k]) or k == 1)
    module = _module_file(parts[:k])
    if module is None:
        return "no such module"
    if k < len(parts) and not _defines(module, parts[k]):
        return f"no module or attribute {parts[k]!r} in {'.'.join(parts[:k])}"
    return None


def _generated_on_install(path: str) -> bool:
    return path.endswith("_version.py")


def _references(path: Path) -> list[tuple[int, str, str]]:
    out = []
    for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        out += [(n, "dotted", m[0]) for m in DOTTED.finditer(line)]
        if path.suffix == ".md":
            out += [(n, "path", m[0]) for m in PATH.finditer(line)]
    return out


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: p.name)
def test_modules_named_in_the_docs_exist(doc: Path) -> None:
    missing = []
    for n, kind, ref in _references(doc):
        if kind == "dotted":
            why = dotted_problem(ref)
        else:
            found = any((r / ref).exists() for r in PATH_ROOTS) or _generated_on_install(ref)
            why = None if found else "no such file"
        if why:
            missing.append(f"{doc.name}:{n}: {ref}: {why}")
    assert not missing, "\n".join(missing)


def test_modules_named_in_docstrings_and_comments_exist() -> None:
    missing = []
    for path in sorted((SRC / "armcli").rglob("*.py")):
        for n, _, ref in _references(path):
            why = dotted_problem(ref)
            if why:
                missing.append(f"{path.relative_to(ROOT)}:{n}: {ref}: {why}")
    assert not missing, "\n".join(missing)


SUBPACKAGES = sorted(p.name for p in (SRC / "armcli").iterdir() if (p / "__init__.py").is_file())
# `urdf.tree` or (sim.rollout: a package-relative name, not a variable's attribute in code
RELATIVE = re.compile(rf"(?<=[`(])(?:{'|'.join(SUBPACKAGES)})\.[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*")


def _prose(path: Path) -> list[tuple[int, str]]:
    """(line, text) of a module's docstrings and comments."""
    text = path.read_text(encoding="utf-8")
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if doc is not None:
                out.append((node.body[0].lineno, doc))
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type == tokenize.COMMENT:
            out.append((tok.start[0], tok.string))
    return out


def test_package_relative_names_in_docstrings_and_comments_exist() -> None:
    missing, seen = [], 0
    for path in sorted((SRC / "armcli").rglob("*.py")):
        for n, text in _prose(path):
            for m in RELATIVE.finditer(text):
                seen += 1
                why = dotted_problem(f"armcli.{m[0]}")
                if why:
                    missing.append(f"{path.relative_to(ROOT)}:{n}: {m[0]}: {why}")
    assert not missing, "\n".join(missing)
    assert seen > 20  # the pattern still finds the source's references


def test_a_stale_name_is_caught() -> None:
    assert dotted_problem("armcli.stability") == "no module or attribute 'stability' in armcli"
    assert dotted_problem("armcli.check.rules.NO_TABLE") is not None
    assert dotted_problem("armcli.sim.states") is None
    assert dotted_problem("armcli.check.rules.RULES") is None
    assert RELATIVE.findall("(`urdf.ground`) and (urdf.xacro_safe: x) but not urdf.links") == [
        "urdf.ground",
        "urdf.xacro_safe",
    ]
