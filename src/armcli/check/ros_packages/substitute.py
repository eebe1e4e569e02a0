"""Launch substitutions resolved from literals only: the pieces all three launch readers share.

A string whose value is partly unknown carries `HOLE` where the unknown part goes, so a
xacro command with one computed argument still names its file and its literal arguments.
`$(...)` substitutions of XML and YAML launch files are expanded here; `$(eval ...)`,
`$(env ...)` and the like become holes (nothing from the file is evaluated as code).
"""

from __future__ import annotations

import ast
import os
import shlex
from collections.abc import Callable, Mapping

from armcli.check.ros_packages.launch_model import Description, Where, package_uri

HOLE = "\x00"  # stands for a part of a string the file does not state literally
XACRO_EXECUTABLES = ("xacro", "xacro.py")
MAX_SUBSTITUTION_DEPTH = 8
MAX_TEXT = 100_000  # [characters] a longer substituted value is not literal
DIRNAME = "\x00dirname"  # the variables' key for $(dirname): the launch file's directory


def known(text: object) -> str | None:
    """`text` when it is a string with no unknown part, else None."""
    return text if isinstance(text, str) and HOLE not in text else None


class Shares:
    """`$(find-pkg-share X)`: X's directory under DIR, else `package://X`; records uses."""

    def __init__(self, dirs: Mapping[str, object]) -> None:
        self.dirs = {k: str(v) for k, v in dirs.items()}
        self.uses: dict[str, int] = {}

    def share(self, name: str, line: int | None = None) -> str:
        """The share directory of package `name` as a launch sees it (source tree = share)."""
        if line is not None:
            self.uses.setdefault(name, line)
        return self.dirs.get(name, package_uri(name))


def join_path(parts: list[str]) -> str:
    """os.path.join of the parts (kept lexical: nothing is looked up)."""
    if sum(len(p) for p in parts) > MAX_TEXT:
        return HOLE
    return os.path.join(*parts) if parts else ""


def xacro_command(text: str, where: Where) -> Description | None:
    """The robot description a `xacro FILE NAME:=VALUE ...` command line loads, if it is one."""
    try:
        tokens = shlex.split(text)
    except ValueError:
        tokens = text.split()
    if not tokens:
        return None
    exe = tokens[0].rsplit("/", 1)[-1]
    if exe not in XACRO_EXECUTABLES or len(tokens) < 2:
        return None
    rest = [t for t in tokens[1:] if t not in ("--inorder", "-i")]
    files = [t for t in rest if ":=" not in t and not t.startswith("-")]
    if not files or HOLE in files[0]:
        return None
    args: dict[str, str] = {}
    dropped: list[str] = []
    for t in rest:
        name, sep, value = t.partition(":=")
        if not sep or HOLE in name:
            continue
        if HOLE in value:
            dropped.append(name)
        else:
            args[name] = value
    return Description(files[0], args, tuple(dropped), where)


def literal_python_expression(text: str) -> object:
    """A launch PythonExpression's value when its text is literal, else None.

    Only comparisons of constants, `x if c else y`, `and`/`or`/`not`; anything else
    (names, calls) is None: nothing is evaluated by Python.
    """
    if HOLE in text:
        return None
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except (SyntaxError, ValueError):
        return None
    return _constant(tree.body, 0)


def _constant(node: ast.AST, depth: int) -> object:
    if depth > MAX_SUBSTITUTION_DEPTH:
        return None
    if isinstance(node, ast.Constant) and isinstance(node.value, str | int | float | bool):
        return node.value
    if isinstance(node, ast.IfExp):
        test = _constant(node.test, depth + 1)
        if isinstance(test, bool):
            return _constant(node.body if test else node.orelse, depth + 1)
        return None
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
        v = _constant(node.operand, depth + 1)
        return (not v) if isinstance(v, bool) else None
    if isinstance(node, ast.BoolOp):
        values = [_constant(v, depth + 1) for v in node.values]
        if not all(isinstance(v, bool) for v in values):
            return None
        return all(values) if isinstance(node.op, ast.And) else any(values)
    if isinstance(node, ast.Compare) and len(node.ops) == 1:
        a, b = _constant(node.left, depth + 1), _constant(node.comparators[0], depth + 1)
        if a is None or b is None:
            return None
        if isinstance(node.ops[0], ast.Eq):
            return a == b
        if isinstance(node.ops[0], ast.NotEq):
            return a != b
    return None


def expand(
    text: str,
    variables: Mapping[str, str | None],
    shares: Shares,
    line: int | None,
    depth: int = 0,
    command: Callable[[str], str] | None = None,
) -> str:
    """XML/YAML launch text with its `$(...)` substitutions expanded (unknown: HOLE)."""
    out: list[str] = []
    i = 0
    while i < len(text):
        start = text.find("$(", i)
        if start < 0:
            out.append(text[i:])
            break
        out.append(text[i:start])
        end = _closing(text, start + 2)
        if end < 0:
            out.append(text[start:])
            break
        inner = text[start + 2 : end]
        out.append(_one(inner, variables, shares, line, depth, command))
        i = end + 1
    result = "".join(out)
    return result if len(result) <= MAX_TEXT else HOLE  # `$(var b)$(var b)` doubling


def _closing(text: str, i: int) -> int:
    """Index of the `)` closing a `$(` opened before `i` (nested ones and quotes counted)."""
    level, quote = 1, ""
    while i < len(text):
        c = text[i]
        if quote:
            quote = "" if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c == "(":
            level += 1
        elif c == ")":
            level -= 1
            if level == 0:
                return i
        i += 1
    return -1


def _one(
    inner: str,
    variables: Mapping[str, str | None],
    shares: Shares,
    line: int | None,
    depth: int,
    command: Callable[[str], str] | None,
) -> str:
    if depth > MAX_SUBSTITUTION_DEPTH:
        return HOLE
    verb, _, rest = inner.strip().partition(" ")
    rest = expand(rest.strip(), variables, shares, line, depth + 1, command)
    arg = rest.strip().strip("'\"")
    if verb in ("find-pkg-share", "find") and known(arg):
        return shares.share(arg, line)
    if verb in ("var", "arg"):
        value = variables.get(arg)
        return value if value is not None else HOLE
    if verb == "dirname":
        return variables.get(DIRNAME) or HOLE  # the launch file's directory
    if verb == "command":
        return command(arg) if command is not None else HOLE
    if verb == "find-exec" and known(arg):
        return arg
    return HOLE  # eval, env, optenv, anon, find-pkg-prefix, ...: not literal
