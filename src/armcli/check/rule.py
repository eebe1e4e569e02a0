"""One `check` rule as the registry (check/rules.py) lists it: id, severity, title, hint."""

from __future__ import annotations

from dataclasses import dataclass

ERROR = "error"
WARNING = "warning"


@dataclass(frozen=True)
class Rule:
    """One check rule: stable id (for --ignore and JSON), severity, title and fix hint.

    `blocks`: while an error of this rule stands, the rule families that need the Pinocchio
    model ("model"), valid masses, centres of mass and joint ranges ("balance": the static
    balance) or usable dynamics numbers ("dynamics") are skipped (check/context.py). An
    inertia tensor error blocks only the dynamics: it moves no centre of mass.
    """

    id: str
    severity: str
    title: str
    hint: str
    blocks: str | None = None
