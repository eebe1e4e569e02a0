"""Did you mean `mass`? The closest valid key for an unknown one in a spec.

The valid keys at a place are the field names (or aliases) of the pydantic models that
can stand there, found by walking the model's annotations along the YAML path (through
Optional, unions, lists and mappings); difflib picks the closest.
"""

from __future__ import annotations

import difflib
import types
import typing
from collections.abc import Sequence
from typing import Any

from pydantic import BaseModel

CUTOFF = 0.6  # difflib similarity below which no suggestion is made


def _expand(tp: Any) -> list[Any]:
    """The concrete types an annotation stands for (Annotated, Optional, unions unwrapped)."""
    origin = typing.get_origin(tp)
    if origin is typing.Annotated:
        return _expand(typing.get_args(tp)[0])
    if origin is typing.Union or origin is types.UnionType:
        return [t for arg in typing.get_args(tp) for t in _expand(arg)]
    return [tp]


def _step(tp: Any, part: str | int) -> list[Any]:
    """The types found one path element below `tp`."""
    out: list[Any] = []
    for t in _expand(tp):
        origin = typing.get_origin(t)
        if isinstance(t, type) and issubclass(t, BaseModel):
            for name, f in t.model_fields.items():
                if part in (name, f.alias):
                    out.append(f.annotation)
        elif origin in (list, tuple, Sequence) and isinstance(part, int):
            out.extend(typing.get_args(t)[:1])
        elif origin is dict:
            out.extend(typing.get_args(t)[1:2])
    return out


def keys_at(model: type[BaseModel], path: Sequence[str | int]) -> list[str]:
    """The keys the spec accepts in the mapping at `path` (empty when none is known)."""
    current: list[Any] = [model]
    for part in path:
        current = [t for tp in current for t in _step(tp, part)]
    names: list[str] = []
    for tp in current:
        for t in _expand(tp):
            if isinstance(t, type) and issubclass(t, BaseModel):
                names += [f.alias or n for n, f in t.model_fields.items()]
    return sorted(set(names))


def did_you_mean(model: type[BaseModel], path: Sequence[str | int]) -> str:
    """`; did you mean 'mass'?` for the unknown key at the end of `path`, or ""."""
    if not path or not isinstance(path[-1], str):
        return ""
    valid = keys_at(model, path[:-1])
    close = difflib.get_close_matches(path[-1], valid, n=1, cutoff=CUTOFF)
    return f"; did you mean {close[0]!r}?" if close else ""
