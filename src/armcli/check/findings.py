"""What a check rule reports: `Finding` (with its place in a spec), `Collector`, `JointRow`.

`apply_policy` turns `--ignore` and `--strict` into the findings a report shows.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from armcli.check.rules import ERROR, RULES, WARNING
from armcli.xacro.lines import Origin

Value = float | int | str | list[float] | None  # what a finding reports


@dataclass(frozen=True)
class SpecPlace:
    """Where in a spec file a finding in its generated URDF comes from (check.spec_locate)."""

    file: str
    line: int | None
    field: str  # dotted field path, e.g. arm.joints.forearm_hand_joint.limit.upper

    def __str__(self) -> str:
        return f"{self.file}:{self.line} {self.field}" if self.line else f"{self.file} {self.field}"


@dataclass(frozen=True)
class Finding:
    """One problem: which rule, where, what the numbers are, and how to fix it."""

    rule: str
    severity: str
    file: str
    line: int | None
    message: str
    values: Mapping[str, Value] = field(default_factory=dict)
    hint: str = ""
    fix: Mapping[str, Value] = field(default_factory=dict)  # the numbers that would pass
    spec: SpecPlace | None = None  # the spec field behind a generated URDF's element
    origin: Origin | None = None  # a xacro expansion's element: the line the user wrote

    @property
    def calls_text(self) -> str:
        """The `(through the macro call at FILE:LINE, ...)` suffix of a macro's element."""
        if self.origin is None or not self.origin.calls:
            return ""
        at = ", then ".join(f"{shown_path(f)}:{n}" for f, n in self.origin.calls)
        return f" (through the macro call at {at})"

    def to_dict(self) -> dict[str, Any]:
        """The finding as a JSON object in the stable schema of docs/check.md."""
        return {
            "rule": self.rule,
            "severity": self.severity,
            "file": self.file,
            "line": self.line,
            "message": self.message,
            "values": dict(self.values),
            "hint": self.hint,
            "fix": dict(self.fix),
            "spec": None if self.spec is None else vars(self.spec).copy(),
            "origin": None
            if self.origin is None
            else {
                "file": self.origin.file,
                "line": self.origin.line,
                "calls": [{"file": f, "line": n} for f, n in self.origin.calls],
            },
        }


def shown_path(path: str) -> str:
    """A path as a message shows it: relative to the working directory when under it."""
    rel = os.path.relpath(path) if os.path.isabs(path) else path
    return path if rel.startswith("..") else rel


class Collector:
    """Builds findings for one file, filling severity and hint from the rule table."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.findings: list[Finding] = []
        self.declared: frozenset[str] | None = None  # the running family's rules (check/run.py)

    def add(
        self,
        rule: str,
        line: int | None,
        message: str,
        fix: Mapping[str, Value] | None = None,
        /,
        **values: Value,
    ) -> None:
        """Record a finding of `rule` at `line`.

        `values` are the numbers behind the message, `fix` the numeric remedy (e.g. the
        inertia that would pass); `fix` is positional-only so no value can shadow it.
        """
        r = RULES[rule]
        if self.declared is not None and rule not in self.declared:  # the gate would miss it
            raise RuntimeError(f"{rule!r} is not among the rules its check family declares")
        self.findings.append(
            Finding(rule, r.severity, self.file, line, message, values, r.hint, dict(fix or {}))
        )

    def has(self, rules: Iterable[str], **values: Value) -> bool:
        """True when a finding of one of `rules` already carries these values (one per problem)."""
        wanted = set(rules)
        return any(
            f.rule in wanted and all(f.values.get(k) == v for k, v in values.items())
            for f in self.findings
        )

    def has_errors(self, rules: Iterable[str] | None = None) -> bool:
        """Whether an error-severity finding was recorded, optionally only among `rules`."""
        wanted = set(rules) if rules is not None else None
        return any(
            f.severity == ERROR and (wanted is None or f.rule in wanted) for f in self.findings
        )


@dataclass(frozen=True)
class JointRow:
    """One joint of the summary table: URDF limits and dynamics [SI], and the gravity load."""

    name: str
    type: str
    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    damping: float
    friction: float
    gravity_max: float | None = None  # worst |gravity torque| over the sample [N·m or N]


def apply_policy(
    findings: Iterable[Finding], *, ignore: Iterable[str] = (), strict: bool = False
) -> list[Finding]:
    """Drop ignored rules; with strict, every warning becomes an error."""
    skip = set(ignore)
    out = []
    for f in findings:
        if f.rule in skip:
            continue
        if strict and f.severity == WARNING:
            f = replace(f, severity=ERROR)
        out.append(f)
    return out
