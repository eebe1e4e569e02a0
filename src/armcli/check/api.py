"""`armcli check` as one library call: the files checked, the policy applied, the verdict.

`check` refuses unusable options first (unknown rule ids, negative payloads, a missing
trajectory), reads the spec to compare with (its layers are imported only then), checks
every usable document (check.inputs), applies --ignore/--strict and says how the run
ends. The report itself is the caller's to print; `Checked.error()` is what the run ends
with after that report (the exit code's exception), or None.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from armcli.check import report
from armcli.check.findings import Finding, apply_policy
from armcli.check.inputs import CheckRun, run_check
from armcli.check.options import CheckOptions, TipoverOptions
from armcli.check.rules import RULES, unknown_rules
from armcli.errors import (
    EXIT_FAILED,
    EXIT_UNUSABLE,
    ArmcliError,
    FindingsError,
    InputError,
    UnusableInputsError,
)
from armcli.urdf.source import Trust
from armcli.xacro.args import XacroInputs


@dataclass(frozen=True)
class Checked:
    """A finished check: every file's results, the findings after the policy, the code."""

    run: CheckRun
    findings: list[Finding]  # by severity, after `ignore` and `strict`
    code: int  # 0, EXIT_FAILED (an error finding) or EXIT_UNUSABLE (nothing usable)

    def error(self) -> ArmcliError | None:
        """The error the run ends with once its report is printed (None: exit 0)."""
        if self.code == EXIT_UNUSABLE:
            unusable = UnusableInputsError([u.error for u in self.run.unusable])
            unusable.reported = True  # in the report the caller printed
            return unusable
        if self.code == EXIT_FAILED:
            n_err = report.counts(self.findings)["error"]
            files = len(self.run.results) + len(self.run.unusable)
            return FindingsError(
                f"{n_err} error finding(s) in {files} file(s)",
                [u.error for u in self.run.unusable],
            )
        return None


def check(
    paths: list[Path],
    options: CheckOptions,
    *,
    spec: Path | None = None,
    ignore: list[str] | tuple[str, ...] = (),
    strict: bool = False,
    trust_xacro: Trust = False,
    inputs: XacroInputs | None = None,
) -> Checked:
    """Check the documents under `paths` (`spec`: a spec to compare their limits with)."""
    unknown = unknown_rules(ignore)
    if unknown:
        raise InputError(f"unknown rule(s) {unknown}; known: {', '.join(RULES)}", field="ignore")
    validate_tipover(options.tipover)
    if spec is not None:  # the spec layers (pydantic, ~0.4 s to import) only for a spec
        from armcli.spec.load import load_spec

        options = replace(options, spec=load_spec(spec))
    run = run_check(paths, options, trust_xacro=trust_xacro, inputs=inputs)
    everything = [f for r in run.results for f in r.findings]
    everything += [u.finding() for u in run.unusable]
    findings = report.by_severity(apply_policy(everything, ignore=ignore, strict=strict))
    return Checked(run, findings, run.exit_code(findings))


def validate_tipover(tip: TipoverOptions) -> None:
    """Refuse balance options that are not usable numbers, naming the field."""
    numbers = (
        ("payload", tip.payload),
        ("min_margin", tip.min_margin),
        ("base_accel", 0.0 if tip.base_accel is None else tip.base_accel),
    )
    for name, x in numbers:
        if not (math.isfinite(x) and x >= 0):
            raise InputError(
                f"must be a finite number >= 0, got {x:g}", field=f"TipoverOptions.{name}"
            )
    if tip.trajectory is not None and not tip.trajectory.is_file():
        raise InputError("no such file", file=tip.trajectory, field="TipoverOptions.trajectory")
