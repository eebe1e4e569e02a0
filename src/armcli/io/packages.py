"""ROS package lookup as ROS tools do it: one resolver for `$(find)`, `package://` and `file://`.

A package NAME is, in this order:

1. `--package-dir NAME=PATH` (the user said so);
2. `<prefix>/share/NAME` for the first prefix of AMENT_PREFIX_PATH whose ament resource
   index registers NAME (`<prefix>/share/ament_index/resource_index/packages/NAME`): what a
   sourced ROS 2 workspace sets and what `ament_index_python` (so real `xacro`) uses;
3. a package found by crawling ROS_PACKAGE_PATH (and the search paths) for package.xml
   files as ROS 1's rospack does: a directory whose package.xml names NAME, whatever the
   directory is called; a package is not searched further, COLCON_IGNORE / AMENT_IGNORE /
   CATKIN_IGNORE and hidden directories are skipped;
4. the package enclosing the file being read: its nearest ancestor whose package.xml
   names NAME (a clone directory may be called anything).

Confinement: a file may be read when its real path (symlinks followed) lies inside a
package root the lookup found. A root counts with two real directories: its own real
path and, when its package.xml is a symlink, the directory that package.xml really lives
in: `colcon build --symlink-install` installs one symlink per file from `share/NAME` into
the source package, and that source package is where its package.xml points. A symlink
to anywhere else still leaves the roots. A root whose real path is `/`, a system
directory or the home directory is no root at all (issue 27: an AMENT_PREFIX_PATH
prefix registering a package whose share dir links to `/` opened every host file).
"""

from __future__ import annotations

import functools
import json
import os
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from armcli.errors import InputError
from armcli.io.mesh_confine import is_package, package_xml_name

IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
AMENT_INDEX = Path("share", "ament_index", "resource_index", "packages")
# real paths that are never a package root: the filesystem root and system directories
SYSTEM_DIRS = frozenset(
    [
        "/",
        "/bin",
        "/boot",
        "/dev",
        "/etc",
        "/home",
        "/lib",
        "/lib32",
        "/lib64",
        "/libx32",
        "/media",
        "/mnt",
        "/opt",
        "/proc",
        "/root",
        "/run",
        "/sbin",
        "/srv",
        "/sys",
        "/tmp",
        "/usr",
        "/usr/bin",
        "/usr/include",
        "/usr/lib",
        "/usr/lib64",
        "/usr/local",
        "/usr/sbin",
        "/usr/share",
        "/var",
        "/var/lib",
        "/var/tmp",
    ]
)
MAX_CRAWL_DIRS = 200_000  # directories visited per ROS_PACKAGE_PATH entry (a typo'd "/")


def _env_paths(variable: str) -> tuple[Path, ...]:
    return tuple(Path(p) for p in os.environ.get(variable, "").split(os.pathsep) if p)


def _absolute(paths: tuple[Path, ...]) -> tuple[Path, ...]:
    """Relative entries against the working directory (not a child's, e.g. the xacro's)."""
    return tuple(Path(os.path.abspath(p)) for p in paths)


def parse_package_dirs(values: list[str]) -> dict[str, Path]:
    """`--package-dir NAME=PATH` options -> {NAME: absolute PATH}.

    A relative PATH starts at the working directory, where the user typed it (the safe
    expander's child runs elsewhere); InputError on a malformed option or a PATH that is
    not a directory (a typo would otherwise surface as "unknown package" later).
    """
    out = {}
    for v in values:
        name, sep, path = v.partition("=")
        if not sep or not name or not path:
            raise InputError(f"expected NAME=PATH, got {v!r}", field="--package-dir")
        where = Path(os.path.abspath(path))
        if not where.is_dir():
            raise InputError(
                f"{v}: {path} is not a directory (from {os.getcwd()})", field="--package-dir"
            )
        out[name] = where
    return out


@dataclass(frozen=True)
class PackageLookup:
    """Where ROS packages are: the CLI's --package-dir plus the ROS environment.

    `ament_prefixes` / `ros_package_path` left as None are read from AMENT_PREFIX_PATH /
    ROS_PACKAGE_PATH when used; `resolved()` fixes them (e.g. to hand to a child process).
    """

    package_dirs: Mapping[str, Path] = field(default_factory=dict)  # --package-dir NAME=PATH
    search_paths: tuple[Path, ...] = ()  # crawled like ROS_PACKAGE_PATH entries, first
    ament_prefixes: tuple[Path, ...] | None = None
    ros_package_path: tuple[Path, ...] | None = None

    def prefixes(self) -> tuple[Path, ...]:
        """The ament install prefixes searched (AMENT_PREFIX_PATH unless given)."""
        if self.ament_prefixes is not None:
            return self.ament_prefixes
        return _env_paths("AMENT_PREFIX_PATH")

    def crawl_paths(self) -> tuple[Path, ...]:
        """The directories crawled for package.xml (search paths, then ROS_PACKAGE_PATH)."""
        env = (
            self.ros_package_path
            if self.ros_package_path is not None
            else _env_paths("ROS_PACKAGE_PATH")
        )
        return (*self.search_paths, *env)

    def resolved(self) -> PackageLookup:
        """The same lookup with the environment read now, every path absolute (from the cwd)."""
        return PackageLookup(
            {k: Path(os.path.abspath(v)) for k, v in self.package_dirs.items()},
            _absolute(self.search_paths),
            _absolute(self.prefixes()),
            _absolute(self.crawl_paths()[len(self.search_paths) :]),
        )

    def with_recorded(self, recorded: Mapping[str, Path], where: str) -> PackageLookup:
        """This lookup plus packages a spec records (`--package-dir` wins over them).

        A recorded directory must be that ROS package (its package.xml names it), so a
        spec can point at a package it was imported with but not at any directory.
        """
        extra = {}
        for name, path in recorded.items():
            if name in self.package_dirs:
                continue
            if package_xml_name(path) != name:
                raise InputError(
                    f"{path} is not the ROS package {name!r} (no package.xml naming it); "
                    f"fix the path or pass --package-dir {name}=PATH",
                    file=where,
                    field=f"packages.{name}",
                )
            extra[name] = Path(os.path.abspath(path))
        if not extra:
            return self
        return replace(self, package_dirs={**extra, **self.package_dirs})

    def find(self, name: str, near: Path | None = None) -> Path | None:
        """The root directory of package `name` (None when unknown); `near`: the file read."""
        if not name or "/" in name or name in (".", ".."):
            return None
        if name in self.package_dirs:
            return Path(os.path.abspath(self.package_dirs[name]))
        for prefix in self.prefixes():
            if (prefix / AMENT_INDEX / name).is_file():
                return Path(os.path.abspath(prefix / "share" / name))
        for entry in self.crawl_paths():
            found = crawl(Path(os.path.abspath(entry))).get(name)
            if found is not None:
                return found
        if near is not None:
            return enclosing_package(near, name)
        return None

    def known(self, near: Path | None = None) -> dict[str, Path]:
        """Every package this lookup can name, first match wins (for a sandbox's resolver)."""
        out: dict[str, Path] = {}
        for entry in reversed(self.crawl_paths()):
            out.update(crawl(Path(os.path.abspath(entry))))
        for prefix in reversed(self.prefixes()):
            index = prefix / AMENT_INDEX
            if index.is_dir():
                out.update(
                    (m.name, Path(os.path.abspath(prefix / "share" / m.name)))
                    for m in index.iterdir()
                    if m.is_file()
                )
        out.update((n, Path(os.path.abspath(p))) for n, p in self.package_dirs.items())
        if near is not None:
            for d in _ancestors(near):
                name = package_xml_name(d)
                if name is not None and name not in out:
                    out[name] = d
        return dict(sorted(out.items()))

    def owner(self, path: Path, near: Path | None = None) -> Path | None:
        """The package root the lookup finds that holds `path` by its name (not following links).

        For `file://` URIs: `/ws/install/share/pkg/meshes/a.stl` belongs to package `pkg`
        when the lookup finds `pkg` at `/ws/install/share/pkg`.
        """
        here = Path(os.path.abspath(path))
        for d in here.parents:
            for name in _names(d):
                found = self.find(name, near)
                if found is not None and Path(os.path.abspath(found)) == d:
                    return d
        return None

    def to_json(self) -> str:
        """This lookup (environment read now) as JSON, for a child process."""
        r = self.resolved()
        return json.dumps(
            {
                "package_dirs": {k: str(v) for k, v in r.package_dirs.items()},
                "search_paths": [str(p) for p in r.search_paths],
                "ament_prefixes": [str(p) for p in r.prefixes()],
                "ros_package_path": [str(p) for p in (r.ros_package_path or ())],
            }
        )

    @classmethod
    def from_json(cls, text: str) -> PackageLookup:
        """The inverse of `to_json`."""
        d = json.loads(text)
        return cls(
            {k: Path(v) for k, v in d["package_dirs"].items()},
            tuple(map(Path, d["search_paths"])),
            tuple(map(Path, d["ament_prefixes"])),
            tuple(map(Path, d["ros_package_path"])),
        )


def _names(directory: Path) -> Iterator[str]:
    """The package names a directory may be the root of: its package.xml's, its own name."""
    declared = package_xml_name(directory)
    if declared is not None:
        yield declared
    if directory.name and directory.name != declared:
        yield directory.name  # <prefix>/share/NAME, registered in the ament index


def _ancestors(near: Path) -> Iterator[Path]:
    here = Path(os.path.abspath(near))
    start = here if here.is_dir() else here.parent
    yield start
    yield from start.parents


def enclosing_package(near: Path, name: str) -> Path | None:
    """The nearest ancestor of `near` that is package `name` (mesh_confine.is_package).

    Its package.xml names it (any directory name), or it is `<prefix>/share/NAME` registered
    in that prefix's ament index (a file inside an install prefix that is not sourced).
    """
    for d in _ancestors(near):
        if is_package(d, name):
            return d
    return None


@functools.lru_cache(maxsize=64)
def crawl(entry: Path) -> dict[str, Path]:
    """Package name -> directory under `entry`, as rospack crawls a ROS_PACKAGE_PATH entry.

    The first package of a name in sorted walk order wins; an entry that is itself a
    package yields just that package.
    """
    out: dict[str, Path] = {}
    visited = 0
    for root, dirs, _files in os.walk(entry, followlinks=True):
        here = Path(root)
        visited += 1
        if visited > MAX_CRAWL_DIRS or any((here / m).exists() for m in IGNORE_MARKERS):
            dirs[:] = []
            continue
        name = package_xml_name(here)
        if name is not None:
            out.setdefault(name, here)
            dirs[:] = []
            continue
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
    return out


def real_roots(root: Path) -> tuple[Path, ...]:
    """The real directories a package root stands for (see the module docstring).

    Its own real path, and the real directory of its package.xml when that is a
    symlink to a package.xml naming the package the root is named after (an install's
    `share/NAME` in a symlink-install tree).
    """
    out = [Path(os.path.realpath(root))]
    xml = root / "package.xml"
    if xml.is_symlink():
        source = Path(os.path.realpath(xml)).parent
        if source not in out and package_xml_name(source) == root.name:
            out.append(source)
    return tuple(r for r in out if usable_root(r))


def usable_root(real: Path) -> bool:
    """Whether a real path may be a package root: not `/`, a system or the home directory."""
    return str(real) not in SYSTEM_DIRS and real != Path(os.path.realpath(Path.home()))


def inside(path: Path, roots: tuple[Path, ...] | list[Path]) -> bool:
    """Whether `path`'s real path (symlinks followed, `..` collapsed) lies inside a root."""
    real = Path(os.path.realpath(path))
    return any(real.is_relative_to(r) for r in roots)
