"""The robot descriptions the packages hold, read as `check` reads any URDF or xacro file.

Which ones: every `.urdf` file, and every `.urdf.xacro` (or other xacro) file a launch
file or a MoveIt config names, expanded with the launch's literal xacro arguments
(`$(find X)` of a package under DIR resolves to it; no other package is looked up unless
`--package-dir` names it). The same file with other arguments is another expansion.
A description that cannot be expanded because it needs a package that is not under DIR,
or an argument the launch computes, is a note (the package rules then do without it);
any other failure is the file's `input-unusable` finding.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

from armcli.check.ros_packages.files import Problem
from armcli.check.ros_packages.launch_model import Description
from armcli.check.ros_packages.workspace import Workspace
from armcli.errors import InputError
from armcli.io.packages import PackageLookup
from armcli.urdf.doc import Urdf
from armcli.urdf.source import Trust, read_urdf_file
from armcli.xacro.args import XacroInputs

URDF_SUFFIXES = (".urdf",)
XACRO_SUFFIXES = (".xacro",)
MAX_DESCRIPTIONS = 64  # expansions per check (each runs the safe xacro evaluator)


@dataclass(frozen=True)
class Loaded:
    """The descriptions read: by key, plus problems (findings) and notes (skipped ones)."""

    urdfs: Mapping[tuple[object, ...], Urdf]
    problems: tuple[Problem, ...]
    notes: tuple[str, ...]


def lookup(ws: Workspace, extra: Mapping[str, Path]) -> PackageLookup:
    """Package lookup for `$(find)` and `package://`: DIR's packages and --package-dir only."""
    return PackageLookup({**ws.dirs, **extra}, (), (), ())


def urdf_files(ws: Workspace) -> list[Description]:
    """Every `.urdf` file under DIR, in packages or not (a plain URDF needs no arguments)."""
    inside = [f for p in ws.packages.values() for f in p.files if f.name.endswith(URDF_SUFFIXES)]
    return [Description(str(f)) for f in [*inside, *ws.loose]]


def load(
    ws: Workspace,
    wanted: Iterable[Description],
    packages: PackageLookup,
    trust: Trust = False,
) -> Loaded:
    """Read every wanted description once (per file and arguments)."""
    urdfs: dict[tuple[object, ...], Urdf] = {}
    problems: list[Problem] = []
    notes: list[str] = []
    seen: set[tuple[object, ...]] = set()
    for d in wanted:
        if d.key in seen:
            continue
        seen.add(d.key)
        path = Path(d.file)
        if not d.file.endswith(URDF_SUFFIXES + XACRO_SUFFIXES):
            continue
        if not (path.is_file() and ws.jail.allows(path)):
            where = d.where.file.rsplit("/", 1)[-1] + f":{d.where.line}" if d.where else "?"
            why = "is outside" if path.exists() else "does not exist under"
            notes.append(
                f"robot description {d.file} (named at {where}) {why} {ws.jail.root}; not checked"
            )
            continue
        if len(urdfs) >= MAX_DESCRIPTIONS:
            notes.append(f"more than {MAX_DESCRIPTIONS} robot descriptions; the rest not checked")
            break
        inputs = XacroInputs(args=dict(d.args), packages=packages)
        try:
            urdfs[d.key] = read_urdf_file(path, trust_xacro=trust, inputs=inputs)
        except InputError as exc:
            _failed(d, exc, problems, notes)
    return Loaded(urdfs, tuple(problems), tuple(notes))


def _failed(d: Description, exc: InputError, problems: list[Problem], notes: list[str]) -> None:
    """A description that did not expand: the user's error, or what DIR does not hold."""
    external = "no package" in exc.message
    if external or d.dropped:
        why = (
            f"the launch's arguments {', '.join(d.dropped)} are not literal"
            if d.dropped and not external
            else exc.message
        )
        args = " ".join(f"{k}:={v}" for k, v in sorted(d.args.items()))
        notes.append(
            f"robot description {d.file}{' ' + args if args else ''} not checked: "
            f"{why} (pass --package-dir NAME=PATH for a package outside DIR)"
        )
        return
    problems.append(Problem.of(exc, d.file))
