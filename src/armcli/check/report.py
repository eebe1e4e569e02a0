"""Render `check` results: a rich table, stable JSON (docs/check.md), GitHub annotations.

Functions return renderables or strings; the command prints them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from typing import Any

from armcli.analysis.rate import round_up
from armcli.check.balance_report import balance_items, reach_items
from armcli.check.findings import Finding, shown_path
from armcli.check.rules import ERROR, WARNING
from armcli.check.run import CheckResult
from armcli.errors import split_source
from armcli.io.jsondoc import dumps
from armcli.io.oneline import decodable, one_line
from armcli.io.terminal import Column, FitTable, Hanging

JSON_SCHEMA = "armcli.check/1"


def counts(findings: Sequence[Finding]) -> dict[str, int]:
    """Number of findings per severity (`error`, `warning`) for the summary and JSON."""
    return {
        ERROR: sum(f.severity == ERROR for f in findings),
        WARNING: sum(f.severity == WARNING for f in findings),
    }


def _summary_dict(r: CheckResult) -> dict[str, Any] | None:
    s = r.summary
    if s is None:
        return None
    d = asdict(s)
    d["poses"] = [{"name": p.name, "q": dict(p.q), "xyz": list(p.xyz)} for p in s.poses]
    return d


def to_json(
    results: Sequence[CheckResult],
    findings: Sequence[Finding],
    exit_code: int,
    unusable: Sequence[tuple[str, str]] = (),
) -> str:
    """The documented JSON document (schema `armcli.check/1`).

    `unusable` lists (file, error message) of inputs that could not be read: each gets an
    entry with `"error"`, its `input-unusable` finding and no summary.
    """
    files = []
    for r in results:
        mine = [f.to_dict() for f in findings if f.file == r.file]
        files.append({"file": r.file, "findings": mine, "summary": _summary_dict(r)})
    for file, error in unusable:
        mine = [f.to_dict() for f in findings if f.file == file]
        files.append({"file": file, "error": error, "findings": mine, "summary": None})
    doc = {
        "schema": JSON_SCHEMA,
        "files": files,
        "counts": counts(findings),
        "exit_code": exit_code,
    }
    return dumps(doc)


def _esc_data(s: str) -> str:
    r"""A workflow command's text: `%`, CR, LF escaped as GitHub reads them; raw bytes `\xff`."""
    return decodable(s).replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _esc_prop(s: str) -> str:
    return _esc_data(s).replace(":", "%3A").replace(",", "%2C")


def to_github(findings: Sequence[Finding]) -> str:
    """GitHub Actions workflow commands: one `::error`/`::warning` line per finding.

    Findings in a URDF built in memory from a spec (`spec.yaml#name.urdf`) point at the
    spec's line of the field they came from (check.spec_locate) and name the generated
    file's line in the message; without a spec field, at the spec file without a line.
    """
    lines = []
    for f in findings:
        path, inner = split_source(f.file)
        if f.origin is not None:  # a xacro element: the file and line the user wrote
            props = [f"file={_esc_prop(shown_path(f.origin.file))}", f"line={f.origin.line}"]
            props.append(f"title={_esc_prop(f'armcli {f.rule}')}")
            msg = f"{f.message}{f.calls_text}" + (f" (fix: {f.hint})" if f.hint else "")
            lines.append(f"::{f.severity} {','.join(props)}::{_esc_data(msg)}")
            continue
        props = [f"file={_esc_prop(path)}"]
        if f.spec is not None and f.spec.line:  # the spec's own line
            props.append(f"line={f.spec.line}")
        elif f.line and not inner:
            props.append(f"line={f.line}")
        props.append(f"title={_esc_prop(f'armcli {f.rule}')}")
        where = f"{inner}:{f.line}: " if inner and f.line else ""
        if f.spec is not None:
            where = f"{f.spec.field} ({where.rstrip(': ') or inner}): "
        msg = f"{where}{f.message}" + (f" (fix: {f.hint})" if f.hint else "")
        lines.append(f"::{f.severity} {','.join(props)}::{_esc_data(msg)}")
    return "".join(line + "\n" for line in lines)


def _num(x: float | None, fmt: str = "{:.4g}") -> str:
    return "-" if x is None else fmt.format(x)


SEVERITY_ORDER = {ERROR: 0, WARNING: 1}
SEVERITY_WIDTH = len(WARNING) + 1  # [columns] the message column starts here


def by_severity(findings: Sequence[Finding]) -> list[Finding]:
    """Errors first, then warnings; the rules' own order within each (a stable sort)."""
    return sorted(findings, key=lambda f: SEVERITY_ORDER.get(f.severity, len(SEVERITY_ORDER)))


def to_rich(
    results: Sequence[CheckResult],
    findings: Sequence[Finding],
    unusable: Sequence[str] = (),
) -> list[Any]:
    """Renderables: per file its findings (errors first) and the summary; then the totals.

    `unusable` names the files that could not be read; their `input-unusable` finding is
    shown like any other. Every renderable keeps its numbers whole at any width.
    """
    from rich.text import Text

    out: list[Any] = []
    files = [(r.file, r) for r in results] + [(u, None) for u in unusable]
    for file, r in files:
        mine = by_severity([f for f in findings if f.file == file])
        out.append(Text(f"\n{one_line(file)}", style="bold"))  # a name's newline is no line
        out.append(_findings_grid(mine) if mine else Text("no findings", style="green"))
        if r is not None:
            out.extend(_summary(r))
    c = counts(findings)
    style = "red" if c[ERROR] else "yellow" if c[WARNING] else "green"
    bad = f", {len(unusable)} unusable" if unusable else ""
    out.append(
        Text(
            f"\n{c[ERROR]} error(s), {c[WARNING]} warning(s) in {len(results)} file(s){bad}",
            style,
        )
    )
    return out


def _findings_grid(findings: Sequence[Finding]) -> Any:
    """Per finding: severity, then rule and place, message, fix and remedy indented beside it."""
    from rich.console import Group
    from rich.text import Text

    items = []
    for f in findings:
        style = "red" if f.severity == ERROR else "yellow"
        body = Text(f.rule, style="bold")
        if f.spec is not None:  # the spec field first; the generated URDF's line after it
            generated = f.file.partition("#")[2]
            body.append(f"  {f.spec}")
            body.append(f" ({generated}:{f.line})" if f.line else "", style="dim")
        elif f.origin is not None:  # a xacro element: where the user wrote it
            body.append(f"  {one_line(shown_path(f.origin.file))}:{f.origin.line}")
            body.append(f" (expanded line {f.line})", style="dim")
        elif f.line:
            body.append(f"  line {f.line}")
        body.append(f"\n{one_line(f.message + f.calls_text)}")
        if f.hint:
            body.append(f"\nfix: {one_line(f.hint)}", style="dim")
        if f.fix:
            body.append(f"\nwrite: {_fix_text(f.fix)}", style="dim")
        items.append(Hanging(Text(f.severity, style=style), body, SEVERITY_WIDTH))
    return Group(*items)


def _fix_text(fix: Any) -> str:
    return " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in fix.items())


JOINT_COLUMNS = (
    ("joint", False),
    ("type", False),
    ("lower\n[rad]", True),
    ("upper\n[rad]", True),
    ("effort\n[N·m]", True),
    ("velocity\n[rad/s]", True),
    ("damping\n[N·m·s]", True),
    ("friction\n[N·m]", True),
    ("gravity\n[N·m]", True),
)
JOINT_CAPTION = (
    "gravity: the largest |gravity torque| over the sampled poses; "
    "prismatic joints in m, N, m/s, N·s/m"
)


def _joint_table(s: Any) -> Any:
    t = FitTable([Column(h, n) for h, n in JOINT_COLUMNS], title="joints", caption=JOINT_CAPTION)
    for j in s.joints:
        t.add_row(
            j.name,
            j.type,
            *(_num(x) for x in (j.lower, j.upper, j.effort, j.velocity, j.damping, j.friction)),
            _num(j.gravity_max),
        )
    return t


def _summary(r: CheckResult) -> list[Any]:
    from rich.text import Text

    s = r.summary
    if s is None:
        return []
    out: list[Any] = [
        Text(f"robot {s.robot!r}: root {s.root}, total mass {s.total_mass:.4g} kg, {s.dof} DoF")
    ]
    if s.joints:
        out.append(_joint_table(s))
    if s.poses:
        t = FitTable(
            [Column("pose", False), Column("x [m]"), Column("y [m]"), Column("z [m]")],
            title=f"end effector {s.end_effector} in {s.root}",
        )
        for p in s.poses:
            t.add_row(p.name, *(f"{v:.4f}" for v in p.xyz))
        out.append(t)
    if s.stability is not None:
        out.append(_stability_text(s.stability, s.rate))
    out.extend(balance_items(s.balance, s.zmp))
    out.extend(reach_items(s.reach, s.reach_points))
    out.extend(Text(n, style="dim") for n in s.notes)
    return out


def _stability_text(st: Any, rate: Any) -> Any:
    from rich.text import Text

    t = Text(
        f"PD stability at dt = {st.dt:g} s: lambda_max(M^-1) = {st.lambda_max:.4g} 1/(kg m^2), "
        + (
            f"gravity's stiffness up to {st.gravity_stiffness:.3g} N·m/rad, "
            if st.gravity_stiffness > 0
            else ""
        )
        + f"Kp up to {st.kp:g}, Kd + damping up to {st.d:g}"
    )
    for v in (st.implicit, st.explicit):
        t.append(f"\n  {v.loop}: ")
        t.append("stable" if v.stable else "UNSTABLE", "green" if v.stable else "red")
        t.append(_loop_bounds(v))
    if rate is not None:
        t.append(
            f"\n  ros2_control controller at {rate.rate:g} Hz (effort held "
            f"{rate.hold * 1e3:.3g} ms): "
        )
        t.append("stable" if rate.stable else "UNSTABLE", "green" if rate.stable else "red")
        edge = "any hold" if rate.hold_max == float("inf") else f"{rate.hold_max * 1e3:.3g} ms"
        t.append(f" (up to a hold of {edge}: update_rate >= {round_up(rate.rate_min, 3):g} Hz)")
    return t


def _loop_bounds(v: Any) -> str:
    """How far a loop is from its edge: the largest dt, and the gain factor at this dt."""
    what = v.scaled
    head = " (up to" if v.stable else " (stable for"
    edge = "dt = " if v.stable else "dt <= "
    dt = "any dt" if v.dt_max == float("inf") else f"{edge}{v.dt_max:.3g} s"
    if v.gain_scale is None:
        return f"{head} {dt}; at this dt gravity or damping alone is too stiff)"
    factor = "any factor" if v.gain_scale == float("inf") else f"x {v.gain_scale:.3g}"
    return f"{head} {dt}, or {what} {factor} at this dt)"
