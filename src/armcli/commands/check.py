"""`armcli check`: lint URDFs (or specs, built in memory) for physical sanity."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import typer

from armcli.check import report
from armcli.check.report import counts
from armcli.check.rules import RULES, CheckOptions, apply_policy
from armcli.check.run import CheckResult, check_urdf
from armcli.commands.options import choice
from armcli.errors import ArmcliError, FindingsError, InputError, UnusableInputsError
from armcli.spec.discover import find_spec
from armcli.spec.load import load_spec
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import parse_package_dirs
from armcli.urdf.source import (
    TRUST_XACRO_HELP,
    UNSANDBOXED_HELP,
    Trust,
    read_robot,
    read_urdf_file,
    trust_mode,
)

FORMATS = ("table", "json", "github")
REPORT_WIDTH = 140  # columns when stdout is not a terminal (CI logs, pipes)


def _documents(path: Path, trust_xacro: Trust) -> list[tuple[Urdf, Any]]:
    """The URDF documents a PATH stands for, each with the spec it came from (or None)."""
    if path.is_dir():
        files = sorted(p for p in path.rglob("*.urdf") if p.is_file())
        if not files:
            raise InputError("no *.urdf files under this directory", file=path)
        return [(read_urdf_file(p, trust_xacro=trust_xacro), None) for p in files]
    robot = read_robot(path, trust_xacro=trust_xacro)
    return [(urdf, robot.spec) for urdf in robot.urdfs]


def _run(
    paths: list[Path], base: CheckOptions, trust_xacro: Trust
) -> tuple[list[CheckResult], list[ArmcliError]]:
    from dataclasses import replace

    results: list[CheckResult] = []
    errors: list[ArmcliError] = []
    for path in paths:
        try:
            docs = _documents(path, trust_xacro)
        except InputError as exc:
            errors.append(exc)
            continue
        for urdf, spec in docs:
            opts = replace(base, spec=spec) if spec is not None else base
            results.append(check_urdf(urdf, opts))
    return results, errors


def check_cmd(
    paths: list[Path] = typer.Argument(
        None,
        help="URDF files, spec YAMLs (built in memory) or directories (every *.urdf); "
        "default: ./armcli.yaml, else the spec in specs/.",
    ),
    spec: Path | None = typer.Option(
        None, "--spec", help="Spec to compare limits with; also gives gains, dt, poses, tool."
    ),
    fmt: str = choice("table", FORMATS, "--format", help="Report format (default: table)."),
    strict: bool = typer.Option(False, "--strict", help="Treat warnings as errors."),
    ignore: list[str] = typer.Option([], "--ignore", help="Silence a rule id (repeatable)."),
    package_dir: list[str] = typer.Option(
        [], "--package-dir", help="NAME=PATH for package://NAME/ mesh URIs (repeatable)."
    ),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Check robot descriptions for physical sanity; exit 1 on error findings."""
    if fmt not in FORMATS:
        raise InputError(f"unknown format {fmt!r}; known: {', '.join(FORMATS)}", field="--format")
    unknown = sorted(set(ignore) - set(RULES))
    if unknown:
        raise InputError(f"unknown rule(s) {unknown}; known: {', '.join(RULES)}", field="--ignore")
    base = CheckOptions(package_dirs=parse_package_dirs(package_dir))
    if spec is not None:
        base = CheckOptions(spec=load_spec(spec), package_dirs=base.package_dirs)
    results, errors = _run(
        list(paths or [find_spec(None)]), base, trust_mode(trust_xacro, unsandboxed)
    )
    findings = apply_policy((f for r in results for f in r.findings), ignore=ignore, strict=strict)
    n_err = counts(findings)["error"]
    code = 2 if errors else (1 if n_err else 0)
    _print(results, findings, fmt, code)
    if errors:
        raise UnusableInputsError(errors)
    if n_err:
        raise FindingsError(f"{n_err} error finding(s) in {len(results)} file(s)")


def _print(results: list[CheckResult], findings: list[Any], fmt: str, code: int) -> None:
    if fmt == "json":
        sys.stdout.write(report.to_json(results, findings, code))
    elif fmt == "github":
        sys.stdout.write(report.to_github(findings))
    elif results:
        from rich.console import Console

        width = None if sys.stdout.isatty() else REPORT_WIDTH
        console = Console(file=sys.stdout, highlight=False, soft_wrap=False, width=width)
        for item in report.to_rich(results, findings):
            console.print(item)


def register(app: typer.Typer) -> None:
    """Add the `check` command to the typer app."""
    app.command("check")(check_cmd)
