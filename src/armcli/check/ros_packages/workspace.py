"""The ROS packages under DIR: found by their package.xml, with their files and dependencies.

As colcon finds them: every directory holding a package.xml is a package (not searched
further); directories with COLCON_IGNORE, AMENT_IGNORE or CATKIN_IGNORE and hidden ones
are skipped. Symlinked directories are not followed and a symlinked file counts only when
it resolves inside DIR. A name found twice (a committed `install/` copy of `src/`) keeps
the shallowest directory. The walk is bounded (directories, files, packages).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from armcli.check.ros_packages.files import Jail, Problem, line_of
from armcli.errors import InputError
from armcli.io.packages import IGNORE_MARKERS

MANIFEST = "package.xml"
MAX_DIRS = 20_000  # directories visited under DIR
MAX_FILES = 50_000  # files listed under DIR
MAX_PACKAGES = 500
SKIPPED_DIRS = frozenset({"__pycache__", "node_modules"})
# package.xml tags that make a package available when another one runs (REP 149)
RUN_DEPENDS = ("depend", "exec_depend", "run_depend", "build_export_depend")


@dataclass(frozen=True)
class Package:
    """One package: its name, directory, manifest and what it depends on at run time."""

    name: str
    root: Path  # absolute, as found under DIR
    manifest: Path
    depends: Mapping[str, int]  # package -> the line of its <depend>/<exec_depend>
    build_type: str  # ament_cmake, ament_python, catkin, ...
    insert_line: int | None  # where a new dependency goes: after the last one
    files: tuple[Path, ...] = ()

    @property
    def ros1(self) -> bool:
        """A catkin (ROS 1) package: its launch files are roslaunch's, not ROS 2's."""
        return self.build_type == "catkin"


@dataclass(frozen=True)
class Workspace:
    """The packages found under DIR and the files that could not be read."""

    jail: Jail
    packages: Mapping[str, Package]
    problems: tuple[Problem, ...] = ()
    notes: tuple[str, ...] = ()
    dirs: Mapping[str, Path] = field(default_factory=dict)  # name -> root, for $(find)
    loose: tuple[Path, ...] = ()  # *.urdf files under DIR outside every package

    def find(self, name: str) -> Path | None:
        """The root of package `name` under DIR, or None."""
        pkg = self.packages.get(name)
        return pkg.root if pkg is not None else None

    def owner(self, path: Path) -> Package | None:
        """The package whose directory holds `path`."""
        best: Package | None = None
        for pkg in self.packages.values():
            if path.is_relative_to(pkg.root) and (
                best is None or len(pkg.root.parts) > len(best.root.parts)
            ):
                best = pkg
        return best


def has_packages(root: Path) -> bool:
    """Whether DIR holds a ROS package (a package.xml at or below it), bounded."""
    for visited, (here, dirs, files) in enumerate(os.walk(root, followlinks=False), start=1):
        if MANIFEST in files or visited > MAX_DIRS:
            return MANIFEST in files
        dirs[:] = _kept(Path(here), dirs)
    return False


def _kept(here: Path, dirs: list[str]) -> list[str]:
    """The subdirectories to walk into: not hidden, not ignored, not a symlink."""
    out = []
    for d in sorted(dirs):
        p = here / d
        if d.startswith(".") or d in SKIPPED_DIRS or p.is_symlink():
            continue
        if any((p / m).exists() for m in IGNORE_MARKERS):
            continue
        out.append(d)
    return out


def discover(root: Path) -> Workspace:
    """Every package under `root` with its files; unreadable manifests as problems."""
    jail = Jail(root)  # paths as the user named DIR: reports show them so (GitHub, SARIF)
    found: dict[str, Package] = {}
    problems: list[Problem] = []
    notes: list[str] = []
    loose: list[Path] = []
    for directory, files in _package_dirs(jail.root, notes, loose):
        try:
            pkg = read_manifest(jail, directory / MANIFEST)
        except InputError as exc:
            problems.append(Problem.of(exc, directory / MANIFEST))
            continue
        if pkg.name in found:
            notes.append(
                f"package {pkg.name!r} found twice: {found[pkg.name].root} kept, {pkg.root} skipped"
            )
            continue
        found[pkg.name] = Package(
            pkg.name, pkg.root, pkg.manifest, pkg.depends, pkg.build_type, pkg.insert_line, files
        )
        if len(found) >= MAX_PACKAGES:
            notes.append(f"stopped after {MAX_PACKAGES} packages")
            break
    return Workspace(
        jail,
        dict(sorted(found.items())),
        tuple(problems),
        tuple(notes),
        {n: p.root for n, p in found.items()},
        tuple(loose),
    )


def _package_dirs(
    root: Path, notes: list[str], loose: list[Path]
) -> list[tuple[Path, tuple[Path, ...]]]:
    """(package directory, its files), shallowest first; bounded walk that follows no link.

    `loose` collects the `*.urdf` files outside every package (checked as before packages).
    """
    packages: list[tuple[Path, list[Path]]] = []
    visited = listed = 0
    for here_s, dirs, files in os.walk(root, followlinks=False):
        here = Path(here_s)
        visited += 1
        if visited > MAX_DIRS or listed > MAX_FILES:
            notes.append(
                f"stopped walking {root} after {MAX_DIRS} directories or {MAX_FILES} files"
            )
            break
        dirs[:] = _kept(here, dirs)
        owner = next((p for p in reversed(packages) if here.is_relative_to(p[0])), None)
        if MANIFEST in files and owner is None:  # inside a package: colcon stops at the outer
            owner = (here, [])
            packages.append(owner)
        if owner is None:
            loose += [here / f for f in sorted(files) if f.endswith(".urdf")]
            continue
        for f in sorted(files):
            listed += 1
            owner[1].append(here / f)
    packages.sort(key=lambda p: (len(p[0].parts), str(p[0])))
    return [(d, tuple(sorted(fs))) for d, fs in packages]


def read_manifest(jail: Jail, path: Path) -> Package:
    """A package.xml -> Package (no files yet); InputError naming the line when unusable."""
    root = jail.xml(path, "package.xml")
    if root.tag != "package":
        raise InputError(
            f"root element is <{root.tag}>, expected <package>", file=path, line=line_of(root)
        )
    name_el = root.find("name")
    name = (name_el.text or "").strip() if name_el is not None else ""
    if not name or "/" in name or name in (".", ".."):
        raise InputError(
            "package.xml has no usable <name>",
            file=path,
            line=line_of(name_el) if name_el is not None else line_of(root),
        )
    depends: dict[str, int] = {}
    last: int | None = None
    for el in root:
        if not isinstance(el.tag, str):
            continue
        if el.tag.endswith("depend"):
            last = line_of(el) or last
        if el.tag in RUN_DEPENDS and el.text and el.text.strip():
            depends.setdefault(el.text.strip(), line_of(el) or 0)
    build_type = (root.findtext("export/build_type") or "").strip()
    if not build_type:
        tools = [(t.text or "").strip() for t in root.findall("buildtool_depend")]
        build_type = "catkin" if "catkin" in tools else (tools[0] if tools else "")
    return Package(name, path.parent, path, depends, build_type, last or line_of(root))
