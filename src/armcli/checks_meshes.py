"""Mesh references: resolve package://, file:// and relative paths; report missing files.

Package lookup order: `--package-dir NAME=PATH`, then ROS_PACKAGE_PATH-style
search paths (each entry is a package or holds packages as subdirectories),
then an ancestor directory of the URDF named NAME whose package.xml names NAME
(the usual `NAME/urdf/robot.urdf` layout).
"""

from __future__ import annotations

import os
from pathlib import Path
from urllib.parse import unquote, urlparse

from armcli.checks import CheckOptions, Collector
from armcli.mesh_confine import is_package
from armcli.urdfdoc import Urdf


def ros_package_path() -> tuple[Path, ...]:
    """The directories listed in $ROS_PACKAGE_PATH (empty when unset)."""
    raw = os.environ.get("ROS_PACKAGE_PATH", "")
    return tuple(Path(p) for p in raw.split(os.pathsep) if p)


def package_root(name: str, urdf_path: Path, opts: CheckOptions) -> Path | None:
    """Where package `name` lives, or None."""
    if name in opts.package_dirs:
        return Path(opts.package_dirs[name])
    for base in (*opts.search_paths, *ros_package_path()):
        if base.name == name and base.is_dir():
            return base
        if (base / name).is_dir():
            return base / name
    for parent in urdf_path.resolve().parents:  # a folder's name alone is not a package
        if parent.name == name and is_package(parent, name):
            return parent
    return None


def resolve(uri: str, urdf_path: Path, opts: CheckOptions) -> Path | None:
    """The local file a mesh URI points to (None if the package is unknown)."""
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name, rel = parsed.netloc, unquote(parsed.path).lstrip("/")
        if not name:  # package:///name/path, seen in the wild and accepted by Pinocchio
            name, _, rel = rel.partition("/")
        root = package_root(name, urdf_path, opts)
        return root / rel if root is not None else None
    if parsed.scheme == "file":
        return Path(unquote(parsed.path))
    if parsed.scheme:
        return None
    p = Path(uri)
    return p if p.is_absolute() else urdf_path.resolve().parent / p


def mesh_paths(urdf: Urdf, opts: CheckOptions) -> dict[str, Path | None]:
    """Every mesh URI in the file -> its resolved path (None if unresolvable or outside
    the allowed roots, so that nothing outside them is ever loaded)."""
    src = Path(urdf.source)
    out: dict[str, Path | None] = {}
    for link in urdf.links:
        for s in (*link.visuals, *link.collisions):
            g = s.geometry
            if g is not None and g.kind == "mesh" and g.filename and g.filename not in out:
                path = resolve(g.filename, src, opts)
                ok = path is not None and confined(g.filename, path, src, opts)
                out[g.filename] = path if ok else None
    return out


def confined(uri: str, path: Path, urdf_path: Path, opts: CheckOptions) -> bool:
    """Whether a resolved mesh path lies inside the allowed roots (robot_source.allowed_roots,
    --package-dir, the search paths, and for package:// the package it names)."""
    from armcli.robot_source import allowed_roots, inside_roots

    extra = [*map(Path, opts.package_dirs.values()), *opts.search_paths]
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name = parsed.netloc or unquote(parsed.path).lstrip("/").partition("/")[0]
        root = package_root(name, urdf_path, opts)
        extra += [root] if root is not None else []
    return inside_roots(path, allowed_roots(urdf_path.parent, extra))


def check(urdf: Urdf, opts: CheckOptions, out: Collector) -> None:
    src = Path(urdf.source)
    reported: set[str] = set()
    for link in urdf.links:
        for s in (*link.visuals, *link.collisions):
            g = s.geometry
            if g is None or g.kind != "mesh" or g.filename in reported:
                continue
            if not g.filename:
                out.add("mesh-missing", g.line, f"link {link.name!r}: mesh without a filename")
                continue
            path = resolve(g.filename, src, opts)
            if path is not None and not confined(g.filename, path, src, opts):  # not stat'ed
                reported.add(g.filename)
                out.add(
                    "mesh-missing",
                    g.line,
                    f"link {link.name!r}: mesh {g.filename!r} resolves to {path}, outside the "
                    "allowed directories (the URDF's directory and ROS package, --package-dir, "
                    "ROS_PACKAGE_PATH); not read",
                    uri=g.filename,
                )
                continue
            if path is None or not path.is_file():
                reported.add(g.filename)
                why = "unknown package" if path is None else f"no file {path}"
                out.add(
                    "mesh-missing",
                    g.line,
                    f"link {link.name!r}: mesh {g.filename!r}: {why}",
                    uri=g.filename,
                )
