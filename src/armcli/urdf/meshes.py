"""Mesh URIs -> local files, one resolver for every command (check, view, render).

Package lookup order: `--package-dir NAME=PATH`, then ROS_PACKAGE_PATH-style
search paths (each entry is a package or holds packages as subdirectories),
then the URDF's directory or an ancestor named NAME whose package.xml names NAME
(the usual `NAME/urdf/robot.urdf` layout). Relative URIs start at the URDF's directory.
A resolved path must lie inside the allowed roots (see `confined`), so a hostile
URDF cannot make armcli read `/etc/passwd` as a mesh.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import unquote, urlparse

from armcli.errors import InputError
from armcli.urdf.doc import Urdf
from armcli.urdf.mesh_confine import is_package
from armcli.urdf.source import allowed_roots, inside_roots


@dataclass(frozen=True)
class MeshSearch:
    """Where package:// URIs may point besides the URDF's own package (from the CLI)."""

    package_dirs: Mapping[str, Path] = field(default_factory=dict)  # --package-dir NAME=PATH
    search_paths: tuple[Path, ...] = ()


def parse_package_dirs(values: list[str]) -> dict[str, Path]:
    """`--package-dir NAME=PATH` options -> {NAME: PATH}; InputError on a malformed one."""
    out = {}
    for v in values:
        name, sep, path = v.partition("=")
        if not sep or not name or not path:
            raise InputError(f"expected NAME=PATH, got {v!r}", field="--package-dir")
        out[name] = Path(path)
    return out


def ros_package_path() -> tuple[Path, ...]:
    """The directories listed in $ROS_PACKAGE_PATH (empty when unset)."""
    raw = os.environ.get("ROS_PACKAGE_PATH", "")
    return tuple(Path(p) for p in raw.split(os.pathsep) if p)


def package_root(name: str, base_dir: Path, search: MeshSearch) -> Path | None:
    """Where package `name` lives, or None."""
    if name in search.package_dirs:
        return Path(search.package_dirs[name])
    for base in (*search.search_paths, *ros_package_path()):
        if base.name == name and base.is_dir():
            return base
        if (base / name).is_dir():
            return base / name
    here = base_dir.resolve()
    for parent in (here, *here.parents):  # a folder's name alone is not a package
        if parent.name == name and is_package(parent, name):
            return parent
    return None


def resolve(uri: str, base_dir: Path, search: MeshSearch) -> Path | None:
    """The local file a mesh URI points to (None if the package is unknown)."""
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name, rel = parsed.netloc, unquote(parsed.path).lstrip("/")
        if not name:  # package:///name/path, seen in the wild and accepted by Pinocchio
            name, _, rel = rel.partition("/")
        root = package_root(name, base_dir, search)
        return root / rel if root is not None else None
    if parsed.scheme == "file":
        return Path(unquote(parsed.path))
    if parsed.scheme:
        return None
    p = Path(uri)
    return p if p.is_absolute() else base_dir.resolve() / p


def mesh_paths(urdf: Urdf, search: MeshSearch) -> dict[str, Path | None]:
    """Every mesh URI in the file -> its resolved path.

    None if unresolvable or outside the allowed roots, so that nothing outside them is
    ever loaded.
    """
    base = Path(urdf.source).parent
    out: dict[str, Path | None] = {}
    for link in urdf.links:
        for s in (*link.visuals, *link.collisions):
            g = s.geometry
            if g is not None and g.kind == "mesh" and g.filename and g.filename not in out:
                path = resolve(g.filename, base, search)
                ok = path is not None and confined(g.filename, path, base, search)
                out[g.filename] = path if ok else None
    return out


def confined(uri: str, path: Path, base_dir: Path, search: MeshSearch) -> bool:
    """Whether a resolved mesh path lies inside the allowed roots.

    The roots: urdf.source.allowed_roots, --package-dir, the search paths, and for
    package:// the package it names.
    """
    extra = [*map(Path, search.package_dirs.values()), *search.search_paths]
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name = parsed.netloc or unquote(parsed.path).lstrip("/").partition("/")[0]
        root = package_root(name, base_dir, search)
        extra += [root] if root is not None else []
    return inside_roots(path, allowed_roots(base_dir, extra))
