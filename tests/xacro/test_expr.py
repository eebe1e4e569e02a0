"""The safe expression evaluator (issue 19): what real description files compute, and no more.

The reference for every accepted expression is Python's own `eval` of the same text
(the evaluator must agree with it); refusals must name the construct.
"""

from __future__ import annotations

import builtins
import math

import pytest

from armcli.xacro.expr import MAX_SEQUENCE, Evaluator, ExprRefusedError

SYMBOLS = {"xyz": "0.1 0.2 0.3", "name": "  Left_Arm ", "joints": ["a", "b"], "pi": math.pi}


def evaluate(text: str) -> object:
    return Evaluator(lambda n: SYMBOLS[n] if n in SYMBOLS else getattr(builtins, n))(text)


ACCEPTED = [
    "dict(joint_1=0.0, joint_2=pi / 2)",  # Kinova's initial positions
    "dict(a=1)['a'] + len(dict(b=2, c=3))",
    "float(xyz.split(' ')[2]) * 2",  # Franka's xyz.split
    "xyz.split()",
    "name.strip().lower()",
    "name.upper().replace('_', '-')",
    "name.strip().startswith('Left') and not name.endswith('x')",
    "'_'.join(joints + ['c'])",
    "list(map(float, xyz.split(' ')))",
    "sorted(joints, reverse=True)",
    "max([3, 1, 2], key=abs)",
    "round(1.23456, ndigits=2)",
    "{'a': 1, 'b': [1, 2]}['b'][1]",
    "[1, 2, 3].index(2) + (1, 2).count(2)",
    "dict(a=1).get('a', 0) + len(list(dict(a=1).items()))",
    "list(range(3)) + list(list(zip([1], [2]))[0][0:1])",
    "xyz.partition(' ')[2].rsplit(' ', 1)[-1]",
]


@pytest.mark.parametrize("text", ACCEPTED)
def test_accepted_expressions_match_python(text: str) -> None:
    assert evaluate(text) == eval(text, {}, dict(SYMBOLS))  # the reference: Python itself


def test_pop_mutates_only_the_files_own_list() -> None:
    # husky's pacs.urdf.xacro: ${int(levels.pop(0).strip())}
    levels = [" 3 ", "4"]
    ev = Evaluator(lambda n: {"levels": levels}[n] if n == "levels" else int)
    assert ev("int(levels.pop(0).strip())") == 3 and levels == ["4"]


REFUSED = [
    ("'{0.__class__}'.format(1)", "attribute access .format on str"),
    ("'%s' % 1", "%-formatting of strings is not allowed"),
    ("name.encode()", "attribute access .encode on str"),
    ("joints.append('x')", "attribute access .append on list"),
    ("dict(**{'a': 1})", r"\* and \*\* unpacking are not allowed"),
    ("max(*joints)", r"\* and \*\* unpacking are not allowed"),
    ("list(map(getattr, [1], ['real']))", "calling getattr|passing getattr"),
    ("sorted(joints, key=type)", "passing type to a call"),
    ("name.__class__", "attribute '__class__' is not allowed"),
    ("dict.fromkeys", "attribute access .fromkeys on type"),
    ("list(range(10 ** 9))", f"range longer than {MAX_SEQUENCE} items"),
    ("('a' * 1000).replace('a', 'a' * 10000)", f"result longer than {MAX_SEQUENCE} items"),
    ("('x' * 1000).join(['y' * 1000] * 1000)", f"result longer than {MAX_SEQUENCE} items"),
    ("(1).real", "attribute access .real on int"),
    ("f'{name}'", "JoinedStr expressions are not allowed"),
]


@pytest.mark.parametrize(("text", "message"), REFUSED, ids=[t for t, _ in REFUSED])
def test_refused(text: str, message: str) -> None:
    with pytest.raises(ExprRefusedError, match=message):
        evaluate(text)


def test_replacement_callables_are_used_when_passed() -> None:
    """A callable with a safe replacement (xacro's load_yaml) is swapped even as an argument."""
    calls: list[str] = []

    def real(_: str) -> str:
        raise AssertionError("the unconfined original ran")

    def safe(x: str) -> str:
        calls.append(x)
        return x.upper()

    ev = Evaluator(lambda n: {"load": real}.get(n) or getattr(builtins, n), {real: safe})
    assert ev("list(map(load, ['a', 'b']))") == ["A", "B"]
    assert ev("load('c')") == "C" and calls == ["a", "b", "c"]
