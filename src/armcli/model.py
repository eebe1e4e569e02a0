"""URDF -> Pinocchio model; the one place parser quirks are handled.

Pinocchio's URDF parser prints problems to stderr (and e.g. turns mass="nan"
into 0) instead of raising, so loading captures the C-level stderr and returns
what it said as warnings for the caller (checks turn them into findings).
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from armcli.errors import InputError


@dataclass
class LoadedModel:
    """A Pinocchio model plus what the parser said while building it."""

    model: Any  # pinocchio.Model
    source: str
    parser_messages: list[str] = field(default_factory=list)


def _capture_stderr(fn: Any) -> tuple[Any, list[str]]:
    """Run fn() with the process-level stderr (fd 2) redirected to a temp file."""
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        saved = os.dup(2)
        try:
            os.dup2(tmp.fileno(), 2)
            result = fn()
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        tmp.seek(0)
        text = tmp.read().decode("utf-8", "replace")
    return result, [ln for ln in text.splitlines() if ln.strip()]


def load_model(path: str | Path, *, xml: str | None = None) -> LoadedModel:
    """Build a fixed-base Pinocchio model from a URDF file (or from `xml` text)."""
    import pinocchio as pin

    source = str(path)
    text = xml if xml is not None else Path(path).read_text(encoding="utf-8")
    try:
        model, messages = _capture_stderr(lambda: pin.buildModelFromXML(text))
    except (RuntimeError, ValueError) as exc:
        raise InputError(f"Pinocchio cannot load this URDF: {exc}", file=source) from None
    return LoadedModel(model=model, source=source, parser_messages=messages)
