"""Spec file -> validated RobotSpec: YAML with line numbers, pydantic, then semantics.

Every problem is reported with its file, line and dotted field path, all at once.
"""

from __future__ import annotations

from pathlib import Path

from pydantic import ValidationError

from armcli.errors import Problem, SpecError
from armcli.io.yaml import YamlDoc, dotted, load_yaml, loads_yaml
from armcli.spec.expand import expand_parts
from armcli.spec.model import RobotSpec
from armcli.spec.semantics import semantic_problems
from armcli.spec.suggest import did_you_mean

MASS_REMEDY = (
    "; a massless link has no inertia to simulate: give its real mass (a few grams for a "
    "sensor or frame), or make it a fixed frame without geometry"
)


def _pydantic_problems(exc: ValidationError, doc: YamlDoc) -> list[Problem]:
    out = []
    for err in exc.errors():
        loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and p[:1].isupper()))
        msg = err["msg"]
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        if err["type"] == "extra_forbidden":
            msg = "unknown key" + did_you_mean(RobotSpec, loc)
        elif err["type"] == "greater_than" and loc and loc[-1] == "mass":
            msg += MASS_REMEDY
        out.append(Problem(dotted(loc), msg, doc.line_of(loc)))
    return out


def spec_from_doc(doc: YamlDoc) -> RobotSpec:
    """Validate parsed YAML into a RobotSpec or raise SpecError listing every problem."""
    if not isinstance(doc.data, dict):
        raise SpecError(doc.source, [Problem("", "a spec must be a YAML mapping", 1)])
    try:
        spec = RobotSpec.model_validate(doc.data)
    except ValidationError as exc:
        raise SpecError(doc.source, _pydantic_problems(exc, doc)) from None
    spec, problems = expand_parts(spec)
    if not problems:
        problems = semantic_problems(spec)
    if problems:
        lines = [Problem(p.field, p.message, doc.line_of(_split(p.field))) for p in problems]
        raise SpecError(doc.source, lines)
    return spec


def _split(field: str) -> tuple[str | int, ...]:
    out: list[str | int] = []
    for part in field.replace("[", ".[").split("."):
        if part.startswith("["):
            out.append(int(part[1:-1]))
        elif part:
            out.append(part)
    return tuple(out)


def load_spec(path: str | Path) -> RobotSpec:
    """Read, parse and validate a spec file (relative mesh paths start at its directory)."""
    return spec_from_doc(load_yaml(path)).with_source(Path(path))


def loads_spec(text: str, source: str = "<string>") -> RobotSpec:
    """Parse and validate spec text; `source` names it in error messages."""
    return spec_from_doc(loads_yaml(text, source))
