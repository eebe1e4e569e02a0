"""The expression language of safe xacro expansion: an AST whitelist instead of `eval`.

xacro evaluates `${...}` with Python's `eval` (builtins removed, but attribute
access, `type`, `vars` and friends remain), which is why a foreign xacro file
is code. Real description files only compute with numbers and strings, so
xacro.safe replaces that `eval` with this walker: literals, property names,
arithmetic, comparisons, boolean logic, conditional expressions, indexing,
`math` functions, pure builtins (with keyword arguments: `dict(joint_1=0.0)`) and
a fixed set of read-only `str` methods plus a few list/dict ones (`xyz.split(' ')`,
`levels.pop(0)`, `d.get(k)`); nothing that formats (`format`, `%`) or reaches
attributes. A callable may only be passed to another (`map(float, xs)`) when it is
itself allowed. Anything else raises ExprRefusedError, which xacro.safe turns into
an error naming the file and line. Sizes are bounded so that `'x' * 4000000000`,
`9 ** 9 ** 9` or `s.replace('a', s)` cannot exhaust memory or time.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Mapping
from typing import Any

MAX_SEQUENCE = 1_000_000  # characters of a string / items of a list an expression may build
MAX_INT_BITS = 4096  # integer results (2 ** 5000 refused; floats overflow on their own)
_MATH_NAMES = [
    "acos",
    "asin",
    "atan",
    "atan2",
    "ceil",
    "cos",
    "cosh",
    "degrees",
    "e",
    "exp",
    "fabs",
    "floor",
    "fmod",
    "hypot",
    "inf",
    "isclose",
    "log",
    "log10",
    "log2",
    "pi",
    "pow",
    "radians",
    "sin",
    "sinh",
    "sqrt",
    "tan",
    "tanh",
    "tau",
    "trunc",
    "copysign",
    "isfinite",
    "isinf",
    "isnan",
]
MATH: dict[str, Any] = {name: getattr(math, name) for name in _MATH_NAMES}
_BUILTINS: tuple[Callable[..., Any], ...] = (
    abs,
    all,
    any,
    bool,
    dict,
    divmod,
    enumerate,
    filter,
    float,
    frozenset,
    int,
    isinstance,
    len,
    list,
    map,
    max,
    min,
    ord,
    range,
    reversed,
    round,
    set,
    sorted,
    str,
    sum,
    tuple,
    zip,
)
# Methods an expression may call: read-only for str; list.pop is xacro files' one mutation
# (husky's pacs.urdf.xacro), on a list the file itself built.
METHODS: dict[type, frozenset[str]] = {
    str: frozenset(
        [
            "capitalize",
            "casefold",
            "count",
            "endswith",
            "find",
            "index",
            "isalnum",
            "isalpha",
            "isdigit",
            "islower",
            "isnumeric",
            "isspace",
            "isupper",
            "join",
            "lower",
            "lstrip",
            "partition",
            "removeprefix",
            "removesuffix",
            "replace",
            "rfind",
            "rindex",
            "rpartition",
            "rsplit",
            "rstrip",
            "split",
            "splitlines",
            "startswith",
            "strip",
            "swapcase",
            "title",
            "upper",
        ]
    ),
    list: frozenset(["count", "index", "pop", "copy"]),
    tuple: frozenset(["count", "index"]),
    dict: frozenset(["get", "keys", "values", "items", "copy"]),
}
_BINOPS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
}
_CMPOPS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
    ast.Is: operator.is_,
    ast.IsNot: operator.is_not,
}


class ExprRefusedError(Exception):
    """An expression uses something outside the whitelist (or beyond the size bounds)."""


class Evaluator:
    """Evaluates one `${...}` expression against xacro's symbol table.

    `lookup(name)` resolves a property (raising KeyError when undefined);
    `calls` maps extra callables (identity) to their safe replacements, e.g.
    xacro's load_yaml to a confined reader.
    """

    def __init__(
        self,
        lookup: Callable[[str], Any],
        calls: Mapping[Any, Callable[..., Any]] | None = None,
    ) -> None:
        self.lookup = lookup
        self.calls = {id(f): safe for f, safe in (calls or {}).items()}
        self.allowed = {id(f) for f in (*_BUILTINS, *MATH.values()) if callable(f)}

    def __call__(self, text: str) -> Any:
        """The value of expression `text`; ExprRefusedError outside the whitelist."""
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except SyntaxError as exc:
            raise ExprRefusedError(f"invalid expression: {exc.msg}") from None
        return self.eval(tree.body)

    def eval(self, node: ast.AST) -> Any:
        """The value of one AST node, dispatched to the `_<NodeType>` method if allowed."""
        method = getattr(self, f"_{type(node).__name__}", None)
        if method is None:
            raise ExprRefusedError(f"{type(node).__name__} expressions are not allowed")
        return method(node)

    def _Constant(self, node: ast.Constant) -> Any:
        if node.value is None or isinstance(node.value, int | float | str | bool):
            return node.value
        raise ExprRefusedError(f"constant {node.value!r} is not allowed")

    def _Name(self, node: ast.Name) -> Any:
        if node.id.startswith("_"):
            raise ExprRefusedError(f"name {node.id!r} is not allowed")
        if node.id in ("True", "False", "None"):
            return {"True": True, "False": False, "None": None}[node.id]
        try:
            return self.lookup(node.id)
        except KeyError:
            raise NameError(f"name {node.id!r} is not defined") from None

    def _Attribute(self, node: ast.Attribute) -> Any:
        if node.attr.startswith("_"):
            raise ExprRefusedError(f"attribute {node.attr!r} is not allowed")
        base = self.eval(node.value)
        kind = next((t for t in METHODS if isinstance(base, t)), None)
        if kind is not None and hasattr(kind, node.attr):  # a method, as in Python (and xacro)
            if node.attr not in METHODS[kind]:
                raise ExprRefusedError(f"attribute access .{node.attr} on {kind.__name__}")
            return Method(base, node.attr)
        if isinstance(base, dict):  # xacro namespaces (math., xacro., included ns) and YAML maps
            try:
                return base[node.attr]
            except KeyError:
                raise NameError(f"name {node.attr!r} is not defined") from None
        raise ExprRefusedError(f"attribute access .{node.attr} on {type(base).__name__}")

    def _Subscript(self, node: ast.Subscript) -> Any:
        base = self.eval(node.value)
        if not isinstance(base, list | tuple | str | dict):
            raise ExprRefusedError(f"indexing a {type(base).__name__}")
        return base[self.eval(node.slice)]

    def _Slice(self, node: ast.Slice) -> slice:
        parts = (node.lower, node.upper, node.step)
        return slice(*(None if p is None else self.eval(p) for p in parts))

    def _List(self, node: ast.List) -> list[Any]:
        return [self.eval(e) for e in node.elts]

    def _Tuple(self, node: ast.Tuple) -> tuple[Any, ...]:
        return tuple(self.eval(e) for e in node.elts)

    def _Dict(self, node: ast.Dict) -> dict[Any, Any]:
        if any(k is None for k in node.keys):
            raise ExprRefusedError("** unpacking is not allowed")
        return {self.eval(k): self.eval(v) for k, v in zip(node.keys, node.values, strict=True)}  # type: ignore[arg-type]

    def _UnaryOp(self, node: ast.UnaryOp) -> Any:
        value = self.eval(node.operand)
        if isinstance(node.op, ast.Not):
            return not value
        if isinstance(node.op, ast.USub):
            return -value
        if isinstance(node.op, ast.UAdd):
            return +value
        raise ExprRefusedError("bitwise operators are not allowed")

    def _BinOp(self, node: ast.BinOp) -> Any:
        op = _BINOPS.get(type(node.op))
        if op is None:
            raise ExprRefusedError(f"operator {type(node.op).__name__} is not allowed")
        left, right = self.eval(node.left), self.eval(node.right)
        _check_sizes(node.op, left, right)
        result = op(left, right)
        if isinstance(result, int) and result.bit_length() > MAX_INT_BITS:
            raise ExprRefusedError(f"integer result larger than 2**{MAX_INT_BITS}")
        return result

    def _BoolOp(self, node: ast.BoolOp) -> Any:
        value: Any = None
        for operand in node.values:
            value = self.eval(operand)
            if isinstance(node.op, ast.And) and not value:
                return value
            if isinstance(node.op, ast.Or) and value:
                return value
        return value

    def _Compare(self, node: ast.Compare) -> bool:
        left = self.eval(node.left)
        for op, comparator in zip(node.ops, node.comparators, strict=True):
            right = self.eval(comparator)
            if not _CMPOPS[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp) -> Any:
        return self.eval(node.body) if self.eval(node.test) else self.eval(node.orelse)

    def _Call(self, node: ast.Call) -> Any:
        func = self.eval(node.func)
        if any(isinstance(a, ast.Starred) for a in node.args) or any(
            k.arg is None for k in node.keywords
        ):
            raise ExprRefusedError("* and ** unpacking are not allowed")
        args = [self._argument(self.eval(a)) for a in node.args]
        kwargs = {str(k.arg): self._argument(self.eval(k.value)) for k in node.keywords}
        if id(func) in self.calls:
            return self.calls[id(func)](*args, **kwargs)
        if not self._allowed(func):
            raise ExprRefusedError(f"calling {getattr(func, '__name__', type(func).__name__)}")
        if func is range and len(range(*args)) > MAX_SEQUENCE:
            raise ExprRefusedError(f"range longer than {MAX_SEQUENCE} items")
        return func(*args, **kwargs)

    def _allowed(self, func: Any) -> bool:
        return isinstance(func, Method) or id(func) in self.allowed

    def _argument(self, value: Any) -> Any:
        """An argument value; a callable one must be allowed (map, sorted's key=, ...)."""
        if callable(value):
            if id(value) in self.calls:
                return self.calls[id(value)]
            if not self._allowed(value):
                name = getattr(value, "__name__", type(value).__name__)
                raise ExprRefusedError(f"passing {name} to a call")
        return value


class Method:
    """A whitelisted method bound to its value (`'a b'.split`), with size bounds."""

    def __init__(self, obj: Any, name: str) -> None:
        self.obj = obj
        self.name = name
        self.__name__ = name

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        """Call the method after checking that its result stays within MAX_SEQUENCE."""
        if self.name == "replace" and len(args) >= 2 and isinstance(args[1], str):
            grows = self.obj.count(args[0]) * max(len(args[1]) - len(args[0]), 0)
            if len(self.obj) + grows > MAX_SEQUENCE:
                raise ExprRefusedError(f"result longer than {MAX_SEQUENCE} items")
        if self.name == "join" and args:
            items = list(args[0])
            if sum(len(str(i)) + len(self.obj) for i in items) > MAX_SEQUENCE:
                raise ExprRefusedError(f"result longer than {MAX_SEQUENCE} items")
            args = (items, *args[1:])
        return getattr(self.obj, self.name)(*args, **kwargs)


def _check_sizes(op: ast.operator, left: Any, right: Any) -> None:
    """Refuse operations whose result would be huge before computing them."""
    if isinstance(op, ast.Mult):
        for seq, count in ((left, right), (right, left)):
            sized = isinstance(seq, str | list | tuple) and isinstance(count, int)
            if sized and len(seq) * max(count, 0) > MAX_SEQUENCE:
                raise ExprRefusedError(f"result longer than {MAX_SEQUENCE} items")
    seqs = isinstance(left, str | list | tuple) and isinstance(right, str | list | tuple)
    if isinstance(op, ast.Add) and seqs and len(left) + len(right) > MAX_SEQUENCE:
        raise ExprRefusedError(f"result longer than {MAX_SEQUENCE} items")
    if isinstance(op, ast.Mod) and isinstance(left, str):
        raise ExprRefusedError("%-formatting of strings is not allowed")
    ints = isinstance(left, int) and isinstance(right, int)
    if (
        isinstance(op, ast.Pow)
        and ints
        and abs(left) > 1
        and right * math.log2(abs(left)) > MAX_INT_BITS
    ):
        raise ExprRefusedError(f"integer result larger than 2**{MAX_INT_BITS}")
