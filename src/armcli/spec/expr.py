"""Safe arithmetic on numbers and `pi`, for angles written as `pi/2` or `-pi/4` in YAML.

Parsed with `ast` and evaluated by walking the tree: never `eval`.
"""

from __future__ import annotations

import ast
import math
import operator

_BINOPS = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
}
_NAMES = {"pi": math.pi}
MAX_EXPR_CHARS = 64


def eval_expr(text: str) -> float:
    """Value of a small expression like `pi/2`, `-pi/4`, `3*pi/4`, `0.5`; ValueError if not one."""
    src = text.strip()
    if not src or len(src) > MAX_EXPR_CHARS:
        raise ValueError(f"not a number or simple expression of pi: {text!r}")
    try:
        tree = ast.parse(src, mode="eval")
    except SyntaxError:
        raise ValueError(f"not a number or simple expression of pi: {text!r}") from None
    value = _eval(tree.body, text)
    if not math.isfinite(value):
        raise ValueError(f"expression is not finite: {text!r}")
    return value


def _eval(node: ast.AST, text: str) -> float:
    if isinstance(node, ast.Constant) and type(node.value) in (int, float):
        value = node.value
        assert isinstance(value, int | float)
        return float(value)
    if isinstance(node, ast.Name) and node.id in _NAMES:
        return _NAMES[node.id]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        v = _eval(node.operand, text)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        left, right = _eval(node.left, text), _eval(node.right, text)
        try:
            return float(_BINOPS[type(node.op)](left, right))
        except ZeroDivisionError:
            raise ValueError(f"division by zero in {text!r}") from None
    raise ValueError(f"only numbers, pi and + - * / are allowed: {text!r}")
