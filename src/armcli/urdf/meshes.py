"""Mesh URIs -> local files, one resolver for every command (check, view, render, export).

`package://NAME/...` resolves through armcli.io.packages (--package-dir,
AMENT_PREFIX_PATH, ROS_PACKAGE_PATH, the enclosing package); relative URIs start at
the URDF's directory. A resolved path must lie inside the allowed roots (see
`confined`), so a hostile URDF cannot make armcli read `/etc/passwd` as a mesh.
"""

from __future__ import annotations

import os
from pathlib import Path
from urllib.parse import unquote, urlparse

from armcli.errors import InputError
from armcli.io.packages import PackageLookup, inside, parse_package_dirs, real_roots
from armcli.urdf.doc import Urdf
from armcli.urdf.source import allowed_roots

# The CLI's package options as the mesh resolver sees them (one lookup for meshes and $(find)).
MeshSearch = PackageLookup
__all__ = [
    "MeshSearch",
    "confined",
    "confined_mesh_xml",
    "mesh_hint",
    "mesh_paths",
    "package_root",
    "parse_package_dirs",
    "resolve",
]


def package_root(name: str, base_dir: Path, search: MeshSearch) -> Path | None:
    """Where package `name` lives (armcli.io.packages' order), or None."""
    return search.find(name, base_dir)


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
        # file:////abs/path (COBOTTA) is file:///abs/path: POSIX keeps a leading `//` in
        # a path as a different root, which made the package lookup miss the file.
        path = unquote(parsed.path)
        return Path("/" + path.lstrip("/") if path.startswith("/") else path)
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

    The roots: urdf.source.allowed_roots, --package-dir, the search paths, for
    `package://` the package it names, and for a `file://` or absolute path the package
    the lookup finds that holds it by name (an install prefix's `share/NAME`). Each package
    root counts with its real directories (packages.real_roots: a symlink-install tree's
    files live in the source package its package.xml points to).
    """
    extra = [*map(Path, search.package_dirs.values()), *search.search_paths]
    parsed = urlparse(uri)
    owner: Path | None = None
    if parsed.scheme == "package":
        name = parsed.netloc or unquote(parsed.path).lstrip("/").partition("/")[0]
        owner = package_root(name, base_dir, search)
    elif parsed.scheme == "file" or (not parsed.scheme and os.path.isabs(uri)):
        owner = search.owner(path, base_dir)
    roots = list(allowed_roots(base_dir, extra))
    if owner is not None:
        roots += real_roots(owner)
    return inside(path, roots)


def mesh_hint(uri: str) -> str:
    """The option that makes `uri` findable: `--package-dir NAME=PATH` for its package."""
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name = parsed.netloc or unquote(parsed.path).lstrip("/").partition("/")[0]
        return (
            f"pass --package-dir {name}=PATH (the directory holding its package.xml) or "
            "put it on AMENT_PREFIX_PATH / ROS_PACKAGE_PATH"
        )
    return "fix the path (relative paths start at the robot file's directory)"


def confined_mesh_xml(
    xml: bytes,
    source: str,
    search: MeshSearch,
    *,
    base_dir: Path | None = None,
    collision_only: bool = False,
) -> str:
    """The URDF text with its mesh filenames replaced by confined, bounded real paths.

    The one route from a URDF to the text Pinocchio reads its geometry from (`check`,
    `plan` through `Robot.collision_model`, `ros-package`'s collision matrix). Pinocchio
    resolves `package://` its own way (the URI path appended to each search directory,
    which reaches paths armcli never checked) and fails with a bare ValueError; here every
    mesh URI is resolved (`resolve`), must be a file inside the allowed roots
    (`confined`), and is replaced by its absolute, symlink-free path, checked to be a
    bounded regular file (`io.mesh_confine.bounded_mesh_file`: size, compressed bombs,
    triangle counts) with all of them under the per-robot total (`check_total`); Pinocchio
    then needs no search directories. A mesh not found or outside the roots is an
    InputError naming it (the first by URI) and the option that fixes it (`mesh_hint`).

    `base_dir`: where relative URIs start; by default the directory of `source` (the URDF
    file). A URDF compiled in memory from a spec passes the spec's directory.
    `collision_only`: only the meshes inside `<collision>` are required and rewritten;
    visual meshes keep their URIs (`ros-package`, `Robot.collision_model`, plan's
    collision matrix: a visual mesh may be another package's, absent on this machine, and
    only collision geometry is loaded). Otherwise every
    `<mesh>` of the document must resolve, so no URI is left for a parser to resolve.
    """
    from lxml import etree

    from armcli.io.mesh_confine import _safe_xml, bounded_mesh_file, check_total

    base = Path(source).parent if base_dir is None else base_dir
    root = etree.fromstring(xml, _safe_xml())
    scopes = root.iter("collision") if collision_only else [root]
    elements = [m for scope in scopes for m in scope.iter("mesh")]
    found: dict[str, Path] = {}
    missing: dict[str, str] = {}
    for uri in dict.fromkeys(el.get("filename", "") for el in elements):
        path = resolve(uri, base, search)
        if path is None or not path.is_file() or not confined(uri, path, base, search):
            missing[uri] = "its package is unknown" if path is None else f"no file {path}"
        else:
            found[uri] = path
    if missing:
        uri = min(missing)
        raise InputError(
            f"mesh {uri!r} cannot be found ({missing[uri]}): {mesh_hint(uri)}", file=source
        )
    real = {uri: bounded_mesh_file(path, source) for uri, path in found.items()}
    check_total(real.values(), source)
    for el in elements:
        el.set("filename", str(real[el.get("filename", "")]))
    text: str = etree.tostring(root, encoding="unicode")
    return text
