"""The spec reference (docs/spec.md), generated from the pydantic models themselves.

Every field's type, default and description (with its unit) come from `RobotSpec`, so the
documentation cannot drift from the validator; a test regenerates it and compares.
Run `python -m armcli.spec.reference > docs/spec.md` after changing a model.
"""

from __future__ import annotations

import sys
import types
import typing
from typing import Any

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from armcli.spec.model import RobotSpec

HEADER = """# Spec reference

Generated from `armcli.spec.model` by `python -m armcli.spec.reference`; do not edit.
SI units throughout, angles in radians; `[rad or m]` means radians for revolute and
metres for prismatic joints. Numbers may be written as expressions of `pi` (`pi/2`).
Unknown keys are errors.
"""


def _type_name(tp: Any) -> str:
    """A short readable name for a field annotation."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is typing.Annotated:
        return _type_name(args[0])
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_name(a) for a in args)
    if origin is typing.Literal:
        return " | ".join(repr(a) for a in args)
    if origin in (dict, list, tuple):
        inner = ", ".join(_type_name(a) for a in args)
        return f"{origin.__name__}[{inner}]"
    if tp is type(None):
        return "null"
    return getattr(tp, "__name__", str(tp))


def _models(model: type[BaseModel], seen: dict[str, type[BaseModel]]) -> None:
    """Collect `model` and every model its fields use, depth first, in field order."""
    if model.__name__ in seen:
        return
    seen[model.__name__] = model
    for info in model.model_fields.values():
        stack = [info.annotation]
        while stack:
            tp = stack.pop(0)
            if isinstance(tp, type) and issubclass(tp, BaseModel):
                _models(tp, seen)
            else:
                stack.extend(typing.get_args(tp))


def _default(info: Any) -> str:
    if info.is_required():
        return "required"
    value = info.default
    if value is PydanticUndefined:
        return "-"
    if isinstance(value, BaseModel):
        return "see below"
    return f"`{value!r}`" if value not in ({}, []) else "empty"


def spec_reference() -> str:
    """The Markdown reference of every spec model, RobotSpec first."""
    seen: dict[str, type[BaseModel]] = {}
    _models(RobotSpec, seen)
    out = [HEADER]
    for name, model in seen.items():
        doc = (model.__doc__ or "").strip().split("\n\n")[0].replace("\n", " ")
        out += [
            f"## {name}",
            "",
            doc,
            "",
            "| field | type | default | meaning |",
            "|---|---|---|---|",
        ]
        for field, info in model.model_fields.items():
            typ = _type_name(info.annotation).replace("|", "\\|")
            out.append(f"| `{field}` | {typ} | {_default(info)} | {info.description or ''} |")
        out.append("")
    return "\n".join(out)


if __name__ == "__main__":
    sys.stdout.write(spec_reference())
