"""`check DIR` over ROS packages: find them, read them, check their robots, run the rules.

The order: packages (workspace.py), MoveIt configs (moveit.py), every launch file as a run
(launches.py), the robot descriptions they name (descriptions.py) checked by `check_urdf`
as any URDF is, then each family of `RULE_FAMILIES` over everything together. Files that
could not be read become `input-unusable` findings on their own line; findings are
grouped per file, and every package's package.xml is listed (clean ones too).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from armcli.check.findings import Finding
from armcli.check.options import CheckOptions
from armcli.check.ros_packages import (
    control_node,
    depends,
    joint_names,
    joint_states,
    plugins,
    sag,
    sim_time,
    srdf_names,
    wheels,
)
from armcli.check.ros_packages.context import PackageContext
from armcli.check.ros_packages.descriptions import load, lookup, urdf_files
from armcli.check.ros_packages.distro import TABLE, detect
from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.launch_model import Description, MoveItLaunch, Node
from armcli.check.ros_packages.launches import Loader, Run, implied_nodes, launch_files
from armcli.check.ros_packages.moveit import MoveItConfig, moveit_configs
from armcli.check.ros_packages.workspace import Package, discover
from armcli.check.rules import RULES
from armcli.check.run import CheckResult, check_urdf
from armcli.urdf.doc import Urdf
from armcli.urdf.source import Trust

RULE_FAMILIES: tuple[tuple[str, Callable[[PackageContext], None]], ...] = (
    ("ros-joint-states-twice", joint_states.check),
    ("ros-control-node-with-sim", control_node.check),
    ("ros-wheel-geometry", wheels.check),
    ("ros-unknown-joint", joint_names.check),
    ("ros-srdf-unknown", srdf_names.check),
    ("ros-classic-plugin", plugins.check),
    ("ros-sim-time", sim_time.check),
    ("ros-start-sag", sag.check),
    ("ros-missing-depend", depends.check),
)


@dataclass(frozen=True)
class PackagesCheck:
    """The outcome: per-file results (descriptions with their summaries) and notes."""

    results: tuple[CheckResult, ...]
    notes: tuple[str, ...]
    distro: str


def check_packages(
    root: Path,
    options: CheckOptions,
    *,
    distro: str | None = None,
    trust: Trust = False,
) -> PackagesCheck:
    """Every package under `root`: its robots as `check` checks a URDF, then the rules."""
    ws = discover(root)
    configs, problems = moveit_configs(ws)
    loader = Loader(ws, lambda m: _implied(m, configs))
    runs = [r for p in ws.packages.values() for f in launch_files(p) if (r := loader.run(f))]
    runs = [_with_moveit(r, configs) for r in runs]
    wanted = [
        *urdf_files(ws),
        *(d for r in runs for d in r.descriptions),
        *(c.description for c in configs if c.description is not None),
    ]
    packages = lookup(ws, options.package_dirs)
    loaded = load(ws, wanted, packages, trust)
    name, why = (distro, "--distro") if distro else detect(_names(loaded.urdfs.values(), runs))
    ctx = PackageContext(
        ws, runs, configs, loaded.urdfs, TABLE[name], spec=options.spec, complete=not loaded.notes
    )
    for _, family in RULE_FAMILIES:
        family(ctx)
    opts = replace(options, package_dirs=dict(packages.package_dirs))
    described = _described(loaded.urdfs.values(), opts)
    bad = [
        *ws.problems,
        *problems,
        *loader.problems.values(),
        *loaded.problems,
        *ctx.problems.values(),
    ]
    found = _unique([*ctx.findings, *(_unusable(p) for p in bad)])
    notes = [
        f"note: {len(ws.packages)} ROS package(s) under {root}: {', '.join(ws.packages) or 'none'}"
        f"; {len(runs)} launch file(s), {len(loaded.urdfs)} robot description(s); distro "
        f"{name} ({why})",
        *(f"note: {n}" for n in (*ws.notes, *loaded.notes)),
    ]
    return PackagesCheck(_results(described, found, ws.packages.values()), tuple(notes), name)


def _implied(m: MoveItLaunch, configs: list[MoveItConfig]) -> list[Node]:
    cfg = next((c for c in configs if c.package.name == m.package), None)
    names = list(cfg.controller_names) if cfg is not None else []
    return implied_nodes(m, names, cfg.ros2_controllers if cfg is not None else None)


def _with_moveit(run: Run, configs: list[MoveItConfig]) -> Run:
    """A run with a MoveIt generator loads that config's robot description."""
    extra: list[Description] = []
    for m in run.moveit:
        cfg = next((c for c in configs if c.package.name == m.package), None)
        if cfg is not None and cfg.description is not None:
            extra.append(cfg.description)
    if not extra:
        return run
    keys = {d.key for d in run.descriptions}
    return replace(run, descriptions=(*run.descriptions, *(d for d in extra if d.key not in keys)))


def _names(urdfs: Iterable[Urdf], runs: list[Run]) -> list[str]:
    """Plugin files, hardware classes and launch packages: the distro's evidence."""
    out = [p.filename or "" for u in urdfs for p in u.plugins]
    out += [rc.hardware for u in urdfs for rc in u.ros2_control]
    out += [n.package or "" for r in runs for n in r.nodes]
    out += [inc.target or "" for r in runs for d in r.docs for inc in d.includes]
    return out


def _described(urdfs: Iterable[Urdf], opts: CheckOptions) -> list[CheckResult]:
    """check_urdf on each description.

    Expansions of one file under several argument sets are one result (their findings
    together, without repeats).
    """
    by_source: dict[str, CheckResult] = {}
    for urdf in urdfs:
        result = check_urdf(urdf, opts)
        if urdf.source in by_source:
            first = by_source[urdf.source]
            merged = _unique([*first.findings, *result.findings])
            by_source[urdf.source] = replace(first, findings=tuple(merged))
        else:
            by_source[urdf.source] = result
    return list(by_source.values())


def _unusable(p: Problem) -> Finding:
    rule = RULES["input-unusable"]
    return Finding(rule.id, rule.severity, p.file, p.line, p.message, {}, rule.hint)


def _unique(findings: Iterable[Finding]) -> list[Finding]:
    seen: set[tuple[object, ...]] = set()
    out = []
    for f in findings:
        where = (f.origin.file, f.origin.line) if f.origin is not None else (f.file, f.line)
        key = (f.rule, *where, f.message)  # an element of several expansions: one finding
        if key not in seen:
            seen.add(key)
            out.append(f)
    return out


def _results(
    described: list[CheckResult], found: list[Finding], packages: Iterable[Package]
) -> tuple[CheckResult, ...]:
    """Descriptions first (with the package findings on their elements), then the rest.

    One result per other file with findings, and every package.xml.
    """
    by_file: dict[str, list[Finding]] = {}
    for f in found:
        by_file.setdefault(f.file, []).append(f)
    out = []
    for r in described:
        out.append(replace(r, findings=(*r.findings, *by_file.pop(r.file, []))))
    files: Mapping[str, list[Finding]] = by_file
    manifests = {str(p.manifest) for p in packages}
    for file in sorted(set(files) | manifests):
        out.append(CheckResult(file, tuple(files.get(file, [])), None))
    return tuple(out)
