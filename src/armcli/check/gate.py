"""`simulate --urdf` refuses a model that `check` reports as an error, with the same rule id.

Pinocchio simulates a zero joint axis, an inertia that violates the triangle
inequality or a negative mass without complaint, and the run then fails late
with a misleading cause ("kinetic energy exceeded", blamed on the gains) or,
worse, succeeds with wrong numbers. Running the same rules as `armcli check`
first makes the two commands agree on what a usable model is.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from armcli.check.options import CheckOptions
from armcli.check.rules import ERROR, RULES, unknown_rules
from armcli.check.run import check_rules
from armcli.errors import InputError, ModelRefusedError, RuleViolation
from armcli.urdf.doc import Urdf

# Errors about what the simulator never reads or what a run itself shows: meshes and colours
# (the dynamics come from <inertial>), contact at named poses, the URDF's name, and a motor
# too weak for gravity (the run reports the saturation).
NOT_SIMULATED = frozenset(
    {
        "mesh-missing",
        "self-collision",
        "material-undefined",
        "rgba-range",
        "robot-name",
        "gravity-effort",
    }
)


def require_known(ignore: Iterable[str]) -> None:
    """Refuse an `ignore` naming no rule: a typo would silence nothing, silently."""
    unknown = unknown_rules(ignore)
    if unknown:
        raise InputError(f"unknown rule(s) {', '.join(unknown)}", field="ignore")


def bears_on_balance(rule: str) -> bool:
    """Whether an error of `rule` on the whole robot changes an arm-only run's tip verdict.

    An arm simulated on a fixed base reads the rest of the robot only for its balance:
    masses, centres of mass and the tree (rules that block the balance stage) and the
    support polygon; a base link's inertia tensor or a wheel's limits do not enter it.
    """
    blocks = getattr(RULES.get(rule), "blocks", None)
    return blocks in ("model", "balance") or rule in ("com-outside-support", "zmp-outside-support")


def refuse_check_errors(
    urdf: Urdf,
    options: CheckOptions | None = None,
    *,
    ignore: Iterable[str] = (),
    only: Callable[[str], bool] | None = None,
) -> None:
    """Raise ModelRefusedError when a check rule that bears on the dynamics reports an error.

    Rules in `ignore` do not refuse (as `check --ignore` silences them): the user has
    judged the finding, e.g. a true `inertia-exceeds-geometry` on an arm whose inertia is
    right although its collision shape is smaller. Only the rule families that can report
    a refusing error run (check.run.check_rules): the gate asks only for what it refuses.
    """
    skip = NOT_SIMULATED | set(ignore)

    def refuses(rule: str) -> bool:
        return rule not in skip and (only is None or only(rule))

    found = check_rules(urdf, options, lambda r: RULES[r].severity == ERROR and refuses(r))
    errors = [
        RuleViolation(f.rule, f.file, f.line, f.message)
        for f in found
        if f.severity == ERROR and refuses(f.rule)
    ]
    if errors:
        raise ModelRefusedError(urdf.source, errors)
