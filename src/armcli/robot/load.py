"""URDF -> Pinocchio model (`Robot.load` calls it); the one place parser quirks are handled.

Pinocchio's URDF parser prints problems to stderr (and e.g. turns mass="nan"
into 0) instead of raising, so loading captures the C-level stderr and returns
what it said as warnings for the caller (checks turn them into findings).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from armcli.errors import InputError, ModelLoadError
from armcli.robot.frames import link_frame as link_frame  # plan/collision.py's, until it moves
from armcli.urdf.doc import Urdf
from armcli.urdf.source import urdf_text


@dataclass
class LoadedModel:
    """A Pinocchio model plus what the parser said while building it."""

    model: Any  # pinocchio.Model
    source: str
    parser_messages: list[str] = field(default_factory=list)


def capture_stderr(fn: Any) -> tuple[Any, list[str]]:
    """Run fn() with the process-level stderr (fd 2) redirected to a temp file.

    If fn raises, the exception gets the captured lines as `parser_messages`.
    """
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        saved = os.dup(2)
        error: BaseException | None = None
        try:
            os.dup2(tmp.fileno(), 2)
            result = fn()
        except BaseException as exc:
            error = exc
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        tmp.seek(0)
        text = tmp.read().decode("utf-8", "replace")
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if error is not None:
        error.parser_messages = lines  # type: ignore[attr-defined]
        raise error
    return result, lines


def parser_problems(lines: Sequence[str]) -> list[str]:
    """The urdfdom messages, one per problem: continuation lines (C++ source locations) dropped."""
    out: list[str] = []
    for ln in lines:
        if ln[:1].isspace():
            continue
        out.append(" ".join(ln.split()))
    return out


def load_model(path: str | Path, *, xml: str | None = None, floating: bool = False) -> LoadedModel:
    """Build a fixed-base Pinocchio model from a URDF file (or from `xml` text).

    `floating`: the root link on a free-flyer joint instead (joint 1, nq = 7, nv = 6), so
    that the root's inertia counts and inverse dynamics gives the wrench holding the base.
    """
    import pinocchio as pin

    source = str(path)
    text = xml if xml is not None else Path(path).read_text(encoding="utf-8")
    args = (pin.JointModelFreeFlyer(),) if floating else ()
    try:
        model, messages = capture_stderr(lambda: pin.buildModelFromXML(text, *args))
    except (RuntimeError, ValueError) as exc:
        said = parser_problems(getattr(exc, "parser_messages", []))
        detail = f" ({'; '.join(said)})" if said else ""
        raise ModelLoadError(
            f"Pinocchio cannot load this URDF: {exc}{detail}", file=source, parser_messages=said
        ) from None
    return LoadedModel(model=model, source=source, parser_messages=messages)


def collision_model(model: Any, xml: str, source: str = "<urdf>") -> Any:
    """The URDF text's collision geometry, a Pinocchio GeometryModel over `model`.

    Meshes are read from the paths the text gives (`Robot.collision_model` resolves and
    confines them first). ModelLoadError when Pinocchio refuses it (a mesh it cannot read).
    """
    import pinocchio as pin

    try:
        gmodel, _ = capture_stderr(
            lambda: pin.buildGeomFromUrdfString(
                model, xml, pin.GeometryType.COLLISION, package_dirs=[]
            )
        )
    except (RuntimeError, ValueError) as exc:
        raise ModelLoadError(
            f"Pinocchio cannot load the collision geometry: {exc}", file=source, parser_messages=[]
        ) from None
    return gmodel


_PROBLEM = {
    "missing": "missing number",
    "not-a-number": "not a number:",
    "non-finite": "non-finite number",
    "length": "wrong number of values:",
}


def checked_model(
    urdf: Urdf, *, gate: Callable[[Urdf], None] | None = None, floating: bool = False
) -> LoadedModel:
    """A parsed URDF -> Pinocchio model, refusing what Pinocchio would silently accept.

    `gate`, when given, may refuse the document after the number checks (e.g.
    check.gate.refuse_check_errors: the model `check` reports as an error).
    """
    if urdf.problems:
        p = urdf.problems[0]
        raise InputError(f"{p.where}: {_PROBLEM[p.kind]} {p.text!r}", file=urdf.source, line=p.line)
    if gate is not None:
        gate(urdf)
    loaded = load_model(urdf.source, xml=urdf_text(urdf), floating=floating)
    said = [m for m in parser_problems(loaded.parser_messages) if "error" in m.lower()]
    if said:
        raise InputError(f"the URDF parser reported: {said[0]}", file=urdf.source)
    return loaded
