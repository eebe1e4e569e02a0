"""Run every `check` rule family on one parsed URDF, in a fixed order."""

from __future__ import annotations

from dataclasses import dataclass

from armcli.check import bodies, inertia, joints, meshes, structure, summary
from armcli.check.rules import CheckOptions, Collector, Finding
from armcli.check.summary import Summary
from armcli.urdf.doc import Urdf


@dataclass(frozen=True)
class CheckResult:
    """The `check` outcome for one file: its findings and the report's summary."""

    file: str
    findings: tuple[Finding, ...]
    summary: Summary | None


def check_urdf(urdf: Urdf, options: CheckOptions | None = None) -> CheckResult:
    """Run every rule on one parsed URDF."""
    opts = options or CheckOptions()
    out = Collector(urdf.source)
    tree = structure.check(urdf, out)
    inertia.check(urdf, tree, out)
    bodies.check(urdf, tree, out)
    joints.check(urdf, opts.spec, out)
    meshes.check(urdf, opts, out)
    model = summary.check(urdf, tree, opts, out)
    return CheckResult(urdf.source, tuple(out.findings), model)
