"""`check` PATH arguments -> checked documents plus the files that could not be used.

Why a module of its own: a directory in someone else's repository can hold a truncated
or empty URDF next to good ones. Every usable file is checked; every unusable one
becomes an `input-unusable` finding (with the reader's message and line), so the table,
the JSON document and SARIF all show it, instead of one bad file hiding the others.
The command decides the exit code from `CheckRun.exit_code`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.check.findings import Finding
from armcli.check.options import CheckOptions
from armcli.check.ros_packages.run import check_packages
from armcli.check.ros_packages.workspace import has_packages
from armcli.check.rules import ERROR, RULES
from armcli.check.run import CheckResult, check_document, check_urdf
from armcli.check.spec_locate import key_lines, locate
from armcli.errors import EXIT_FAILED, EXIT_OK, EXIT_UNUSABLE, InputError
from armcli.io.yaml import load_yaml, read_text
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf
from armcli.urdf.source import RobotFile, Trust, read_robot, read_urdf_file
from armcli.xacro.args import XacroInputs

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

URDF_GLOB = "*.urdf"


@dataclass(frozen=True)
class Unusable:
    """An input file that could not be read as a robot description."""

    file: str
    error: InputError
    named: bool  # given on the command line (not found inside a directory)

    def finding(self) -> Finding:
        """The `input-unusable` finding that stands for this file in every report."""
        rule = RULES["input-unusable"]
        return Finding(
            rule.id, rule.severity, self.file, self.error.line, self.error.message, {}, rule.hint
        )


@dataclass(frozen=True)
class CheckRun:
    """Everything one `armcli check` invocation checked or failed to read."""

    results: tuple[CheckResult, ...]
    unusable: tuple[Unusable, ...]
    notes: tuple[tuple[str, str], ...] = ()  # (file, line) of Urdf.notes: xacro arguments used

    def exit_code(self, findings: list[Finding]) -> int:
        """2 if nothing was usable or a named file was not; else 1 on error findings, else 0.

        `findings` are after --ignore/--strict and include the unusable files' findings,
        so an unreadable file inside a directory counts as an error (exit 1).
        """
        if not self.results or any(u.named for u in self.unusable):
            return EXIT_UNUSABLE
        return EXIT_FAILED if any(f.severity == ERROR for f in findings) else EXIT_OK


def _documents(
    path: Path, trust_xacro: Trust, inputs: XacroInputs | None = None
) -> tuple[list[tuple[Urdf, RobotFile | None]], list[Unusable]]:
    """The URDF documents a PATH stands for, each with its file (or None); the unusable files."""
    if not path.is_dir():
        robot = read_robot(path, trust_xacro=trust_xacro, inputs=inputs)
        return [(urdf, robot) for urdf in robot.urdfs], []
    files = sorted(p for p in path.rglob(URDF_GLOB) if p.is_file())
    if not files:
        raise InputError(f"no {URDF_GLOB} files under this directory", file=path)
    docs: list[tuple[Urdf, RobotFile | None]] = []
    bad: list[Unusable] = []
    for p in files:
        try:
            docs.append((read_urdf_file(p, trust_xacro=trust_xacro, inputs=inputs), None))
        except InputError as exc:
            bad.append(Unusable(str(p), exc, named=False))
    return docs, bad


def run_check(
    paths: list[Path],
    base: CheckOptions,
    *,
    trust_xacro: Trust = False,
    inputs: XacroInputs | None = None,
) -> CheckRun:
    """Check every usable document under `paths`; collect the unusable ones.

    `inputs`: xacro arguments, --env values and package lookup for xacro files.
    """
    results: list[CheckResult] = []
    unusable: list[Unusable] = []
    notes: list[tuple[str, str]] = []
    for path in paths:
        if path.is_dir() and has_packages(path):  # ROS packages: their robots and the rules
            pc = check_packages(path, base, distro=base.ros_distro, trust=trust_xacro)
            results.extend(pc.results)
            notes += [(str(path), n) for n in pc.notes]
            continue
        try:
            docs, bad = _documents(path, trust_xacro, inputs)
        except InputError as exc:
            unusable.append(Unusable(str(path), exc, named=True))
            continue
        unusable.extend(bad)
        has_spec = any(f is not None and f.spec is not None for _, f in docs)
        spec_doc = load_yaml(path) if has_spec else None
        keys = key_lines(read_text(path)) if spec_doc is not None else {}
        for urdf, file in docs:
            spec = file.spec if file is not None else None
            opts = replace(base, spec=spec, robot_file=file) if spec is not None else base
            result = check_urdf(urdf, opts)
            if spec_doc is not None and spec is not None:  # point at the spec, not its URDF
                found = locate(result.findings, urdf.text, spec_doc, keys)
                result = replace(result, findings=tuple(found))
            results.append(result)
            notes += [(urdf.source, line) for line in urdf.notes]
    return CheckRun(tuple(results), tuple(unusable), tuple(notes))


def spec_document_errors(path: Path, urdfs: dict[str, bytes], spec: RobotSpec) -> list[Finding]:
    """The errors `check` reports from a spec's built URDFs (`name` -> bytes), model-free.

    Each once, pointing at the spec: what `build` prints.
    """
    doc, keys = load_yaml(path), key_lines(read_text(path))
    out: list[Finding] = []
    seen: set[tuple[str, str]] = set()
    for name in sorted(urdfs):
        urdf = parse_urdf(urdfs[name], f"{path}#{name}")
        found = check_document(urdf, CheckOptions(spec=spec))
        for f in locate([f for f in found if f.severity == ERROR], urdf.text, doc, keys):
            if (f.rule, f.message) not in seen:
                seen.add((f.rule, f.message))
                out.append(f)
    return out
