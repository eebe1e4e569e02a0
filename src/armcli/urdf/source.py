"""Robot file argument -> URDF documents, the same way for every command.

A path given to `check`, `view`, `render`, `tree` (and `simulate --urdf`) is one
of: a spec YAML (built in memory, nothing written), a URDF (read by urdf.read's
strict reader) or a xacro file. Xacro runs Python from the file, so a foreign
one is expanded in safe mode (xacro.safe: no code runs, files confined) unless
the user passes `--trust-xacro` (xacro itself, sandboxed by xacro.sandbox).
Mesh URIs may only resolve inside the allowed roots, so a hostile URDF cannot make armcli read
`/etc/passwd` as a "mesh".
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.defaults import STANDALONE_ARM_URDF
from armcli.errors import EXPANDED_TAG, InputError, XacroRefusedError
from armcli.io.packages import PackageLookup, inside, real_roots
from armcli.urdf.doc import Urdf
from armcli.urdf.read import parse_urdf, read_urdf
from armcli.xacro.args import Expansion, XacroInputs
from armcli.xacro.lines import parse_map
from armcli.xacro.trust import Trust as Trust  # re-exported: read_robot and callers share it

if TYPE_CHECKING:
    from armcli.spec.model import RobotSpec

SPEC_SUFFIXES = (".yaml", ".yml")
XACRO_SUFFIX = ".xacro"
TRUSTED_ENV_REFUSED = ("LD_", "PYTHON")  # --env names that would change how the child runs


@dataclass(frozen=True)
class RobotFile:
    """What a robot file argument stands for, read once and handed down.

    Its URDF document(s) (a spec's compiled in memory, a xacro file's expanded), for a
    spec the spec, and the `Robot`s built from them: `robots` is filled by
    `armcli.robot.file.robot_of` (this layer sits below the robot handle), one per
    document and loading mode, so every library call a command makes shares them.
    """

    path: Path
    urdfs: tuple[Urdf, ...]  # a spec gives the whole robot and the standalone arm
    spec: RobotSpec | None = None  # its control settings (gains, dt, poses) and tool point
    compiled: bool = False  # the documents are the spec's own, not a URDF read beside it
    robots: dict[tuple[str, bool, bool], object] = field(
        default_factory=dict, compare=False, hash=False, repr=False
    )

    @classmethod
    def of_spec(cls, spec: RobotSpec, path: Path | None = None) -> RobotFile:
        """A loaded spec's robot file: its xacro set compiled and parsed, once."""
        path = path if path is not None else Path(spec.source_file)
        urdfs = spec_urdfs(spec)
        docs = tuple(parse_urdf(urdfs[n], f"{path}#{n}") for n in sorted(urdfs))
        return cls(path, docs, spec, compiled=True)

    def with_spec(self, spec: RobotSpec) -> RobotFile:
        """This URDF run with a spec's settings (`simulate SPEC --urdf FILE`), no robot built.

        A spec that mounts the arm on a base adds its compiled documents after a URDF file's
        (not a xacro file's): the whole robot a fixed-base run's balance stands on
        (`sim.tipping.whole_robot`).
        """
        urdf = self.urdfs[0].source.endswith(".urdf")
        extra = RobotFile.of_spec(spec).urdfs if urdf and spec.mounted_base() is not None else ()
        return RobotFile(self.path, self.urdfs + extra, spec)

    def document(self, name: str) -> Urdf | None:
        """A spec's document by file name (`my_robot.urdf`), None when it has none so named."""
        return next((u for u in self.urdfs if u.source.endswith(f"#{name}")), None)

    @property
    def robot(self) -> Urdf:
        """The whole robot: the spec's `<name>.urdf`, else the only document."""
        if self.compiled and self.spec is not None:
            for name in (f"{self.spec.name}.urdf", STANDALONE_ARM_URDF):
                found = self.document(name)
                if found is not None:
                    return found
        return self.urdfs[0]

    @property
    def arm(self) -> Urdf:
        """What a fixed-base run simulates: a spec's standalone arm, else the only document."""
        found = self.document(STANDALONE_ARM_URDF) if self.compiled else None
        return found if found is not None else self.urdfs[0]


@dataclass(frozen=True)
class RobotInput:
    """The robot a command was given: its file(s), xacro's inputs and how far xacro is trusted.

    What the shared option group of the commands parses (`commands.robot_input`), so a
    library caller names a robot the same way: `RobotInput(Path("r.urdf.xacro")).read()`.
    No file means the spec found from the working directory (armcli.spec.discover).
    """

    paths: tuple[Path, ...] = ()  # `check` takes several; the other commands one or none
    xacro: XacroInputs = field(default_factory=XacroInputs)
    trust: Trust = False

    @property
    def path(self) -> Path | None:
        """The one file named, or None (the spec is found)."""
        return self.paths[0] if self.paths else None

    @property
    def packages(self) -> PackageLookup:
        """Where `$(find NAME)` and `package://NAME/` resolve (--package-dir, the environment)."""
        return self.xacro.packages

    def files(self) -> list[Path]:
        """The files named, or the spec found: ./armcli.yaml, else the one in specs/."""
        from armcli.spec.discover import find_spec  # light: no pydantic

        return list(self.paths) or [find_spec(None)]

    def file(self) -> Path:
        """The one file named, or the spec found."""
        return self.files()[0]

    def read(self, path: Path | None = None) -> RobotFile:
        """The robot's documents (`read_robot`), of `path` or of `file()`."""
        return read_robot(path or self.file(), trust_xacro=self.trust, inputs=self.xacro)


def read_robot(
    path: Path, *, trust_xacro: Trust = False, inputs: XacroInputs | None = None
) -> RobotFile:
    """Spec YAML, URDF or xacro -> RobotFile; InputError when unusable.

    `inputs`: a xacro file's arguments, --env values and package lookup (xacro.args).
    """
    if path.is_dir():
        raise InputError("is a directory, expected a robot spec, URDF or xacro file", file=path)
    if path.suffix in SPEC_SUFFIXES:
        # the spec layers (pydantic models, ~0.3 s to import) only when a spec is read
        from armcli.spec.load import load_spec

        spec = load_spec(path)
        lookup_for(spec, inputs.packages if inputs is not None else None)  # refuse a bad one now
        return RobotFile.of_spec(spec, path)
    return RobotFile(path, (read_urdf_file(path, trust_xacro=trust_xacro, inputs=inputs),))


def spec_urdfs(spec: RobotSpec) -> dict[str, bytes]:
    """URDF file name -> expanded bytes of the spec's xacro set, compiled at each call.

    For the commands that write or compare the bytes (build, import, ros-package); a
    library call that reads the robot is handed its `RobotFile` instead (compiled once).
    """
    from armcli.compiler.expand import expand_urdfs  # the spec compiler: only for a spec

    return expand_urdfs(spec)


def lookup_for(spec: RobotSpec | None, search: PackageLookup | None = None) -> PackageLookup:
    """The package lookup for a robot: the CLI's options plus the packages its spec records."""
    base = search if search is not None else PackageLookup()
    if spec is None or not spec.packages:
        return base
    return base.with_recorded(spec.package_dirs(), spec.source_file)


def read_urdf_file(
    path: Path, *, trust_xacro: Trust = False, inputs: XacroInputs | None = None
) -> Urdf:
    """A URDF or xacro file -> Urdf (xacro by suffix or content).

    A xacro file is expanded in safe mode (xacro.safe: no code from the file runs), or
    with xacro itself when trusted; `Urdf.notes` says which arguments it used.
    """
    if path.suffix != XACRO_SUFFIX:
        try:
            return read_urdf(path)
        except XacroRefusedError:
            pass  # xacro content in a .urdf: expanded like a .xacro file
    xml, used = expand_xacro(path, trust_xacro=trust_xacro, inputs=inputs)
    doc = parse_urdf(xml, f"{path}{EXPANDED_TAG}")
    return replace(doc, notes=used.notes(), origins=parse_map(used.source_map))


def expand_xacro(
    path: Path, *, trust_xacro: Trust = False, inputs: XacroInputs | None = None
) -> tuple[bytes, Expansion]:
    """A xacro file's expansion (the bytes xacro itself writes) and what it used.

    Safe mode (xacro.safe, in a limited child) unless `trust_xacro`: then xacro itself
    in xacro.sandbox's jail, which reports no argument use.
    """
    # imported here: reading a plain URDF (e.g. simulate --urdf) never loads the xacro stack
    from armcli.xacro.safe import request_json
    from armcli.xacro.sandbox import run_safe

    given = inputs or XacroInputs()
    if trust_xacro:
        return _expand_trusted(path, given, unsandboxed=trust_xacro == "unsandboxed")
    request = request_json(allowed_roots(path.parent), given)
    xml, report = run_safe(path, request)  # safe mode: no code runs
    return xml, Expansion.from_dict(report.get("expansion", {}))


def _expand_trusted(
    path: Path, given: XacroInputs, *, unsandboxed: bool
) -> tuple[bytes, Expansion]:
    """Xacro itself in xacro.sandbox's jail, `$(find)` answered by armcli's package lookup.

    Every package the lookup knows is passed in with its directories bound read-only
    (the install prefixes' share/ and each package's real roots: a symlink-install tree
    points into the sources).
    """
    refused = sorted(k for k in given.env if k.startswith(TRUSTED_ENV_REFUSED) or k == "PATH")
    if refused:
        raise InputError(
            f"{refused[0]} may not be set for the xacro child (it would change how Python "
            "or the loader runs)",
            field="--env",
        )
    from armcli.xacro.sandbox import run_trusted

    known = given.packages.known(near=path)
    roots = [*allowed_roots(path.parent), *(p / "share" for p in given.packages.prefixes())]
    roots += [r for root in known.values() for r in real_roots(root)]
    xml, report = run_trusted(
        path,
        mappings=given.args,
        packages=known,
        environ=given.env,
        unsandboxed=unsandboxed,
        roots=roots,
    )
    return xml, Expansion.from_dict(report.get("expansion", {}))


def urdf_text(urdf: Urdf) -> str:
    """The document as text for parsers that take str (Pinocchio, yourdfpy)."""
    try:
        return urdf.text.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError("URDF is not UTF-8 text", file=urdf.source) from None


def allowed_roots(urdf_dir: Path, extra: Iterable[Path] = ()) -> tuple[Path, ...]:
    """Directories mesh files may come from.

    The URDF's directory, the ROS package it sits in (nearest ancestor with a package.xml,
    with its real directories: packages.real_roots), `extra` (--package-dir) and
    ROS_PACKAGE_PATH.
    """
    here = urdf_dir.resolve()
    roots = [here, *extra]
    roots += [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    lexical = Path(os.path.abspath(urdf_dir))
    for start in dict.fromkeys((lexical, here)):  # an install tree's own dir or its source's
        package = next((d for d in (start, *start.parents) if (d / "package.xml").is_file()), None)
        if package is not None:
            roots += real_roots(package)
    return tuple(dict.fromkeys(r.resolve() for r in roots))


def inside_roots(path: Path, roots: Iterable[Path]) -> bool:
    """Whether `path` (symlinks followed, `..` collapsed) lies inside one of `roots`."""
    return inside(path, tuple(roots))
