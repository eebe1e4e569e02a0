"""ROS 2 Python launch files from templates shipped in `armcli/data/`.

Launch files are Python, so they are written as readable templates with
`$name` placeholders. Every substituted value must be a plain name or file
name (no quotes, no code), and the result is parsed before it is returned:
a template that does not compile is a bug and raises BuildError instead of
being written.
"""

from __future__ import annotations

import ast
import re
from importlib import resources
from string import Template

from armcli.errors import BuildError

_SAFE = re.compile(r"^[A-Za-z0-9_./-]*$")
_UNSAFE_TEXT = re.compile(r"[^A-Za-z0-9_.,/ \n-]")


def _template(name: str) -> Template:
    return Template(resources.files("armcli").joinpath("data", name).read_text("utf-8"))


def module_constants(tree: ast.Module) -> dict[str, object]:
    """Module-level `NAME = "literal"` assignments of a parsed launch file."""
    out: dict[str, object] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
            for target in node.targets:
                if isinstance(target, ast.Name):
                    out[target.id] = node.value.value
    return out


def render(template: str, values: dict[str, str], generated_by: str = "") -> bytes:
    """Substitute `values` into the template and check the result parses as intended."""
    for key, value in values.items():
        if not _SAFE.match(value):
            raise BuildError(f"launch template {template}: unsafe value for {key}: {value!r}")
    try:
        note = _UNSAFE_TEXT.sub("_", generated_by)
        text = _template(template).substitute(values, generated_by=note)
    except (KeyError, ValueError) as exc:
        raise BuildError(f"launch template {template}: missing value {exc}") from None
    try:
        tree = ast.parse(text, filename=template)
        compile(tree, template, "exec")
    except SyntaxError as exc:
        raise BuildError(f"launch template {template} does not compile: {exc}") from None
    if "generate_launch_description" not in {
        n.name for n in tree.body if isinstance(n, ast.FunctionDef)
    }:
        raise BuildError(f"launch template {template}: no generate_launch_description()")
    return text.encode("utf-8")
