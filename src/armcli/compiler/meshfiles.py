"""Where a spec's mesh files are, and how a generated URDF names them.

A spec names a mesh as `package://NAME/path`, `file:///abs/path`, an absolute path, or
a path relative to the spec file. `build` keeps every mesh where it is: a relative path
is rewritten relative to the directory the URDF is written to, and a URDF built in
memory (for check, simulate, view) names it by absolute path. `ros-package` copies
path-named meshes into the description package and names them `package://`.

`locate` finds the file (for mesh-derived inertias): `package://NAME` is looked up as
ROS does, in the spec's enclosing package (its package.xml names NAME), then
$ROS_PACKAGE_PATH, then `<prefix>/share/NAME` of $AMENT_PREFIX_PATH.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import unquote, urlparse

from armcli.errors import InputError
from armcli.spec.model import RobotSpec

MESH_DIR = "meshes"  # where ros-package puts copied meshes in the description package
_PACKAGE_NAME = re.compile(rb"<name>\s*([^<\s]+)\s*</name>")


def is_path(filename: str) -> bool:
    """Whether `filename` is a file path (relative or absolute), not a package:// or file:// URI."""
    return urlparse(filename).scheme not in ("package", "file")


def _package_dir(name: str, base_dir: Path) -> Path | None:
    here = base_dir.resolve()
    for d in (here, *here.parents):
        xml = d / "package.xml"
        if xml.is_file():
            m = _PACKAGE_NAME.search(xml.read_bytes()[:100_000])
            if m and m.group(1).decode("utf-8", "replace") == name:
                return d
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry and (Path(entry) / name).is_dir():
            return Path(entry) / name
        if entry and Path(entry).name == name and Path(entry).is_dir():
            return Path(entry)
    for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        share = Path(prefix) / "share" / name
        if prefix and share.is_dir():
            return share
    return None


def locate(filename: str, base_dir: Path, field: str | None = None) -> Path:
    """The local file a spec mesh name points to; InputError naming it when not found."""
    parsed = urlparse(filename)
    if parsed.scheme == "package":
        name, rel = parsed.netloc, unquote(parsed.path).lstrip("/")
        if not name:
            name, _, rel = rel.partition("/")
        root = _package_dir(name, base_dir)
        if root is None:
            raise InputError(
                f"mesh {filename}: package {name!r} not found (the spec's enclosing package, "
                "ROS_PACKAGE_PATH, AMENT_PREFIX_PATH)",
                field=field,
            )
        path = root / rel
    elif parsed.scheme == "file":
        path = Path(unquote(parsed.path))
    else:
        path = Path(filename) if Path(filename).is_absolute() else base_dir / filename
    if not path.is_file():
        raise InputError(f"mesh file {filename} not found ({path})", field=field)
    return path


@dataclass(frozen=True)
class MeshNames:
    """How a generated URDF names the spec's mesh files.

    `base_dir` is the spec's directory; `out_dir` the directory the URDF is written to
    (None: built in memory, absolute paths); `package` the description package that
    `ros-package` copies path-named meshes into (None: they stay where they are).
    """

    base_dir: Path
    out_dir: Path | None = None
    package: str | None = None

    def uri(self, filename: str) -> str:
        """The name of `filename` in the generated URDF."""
        if not is_path(filename):
            return filename
        if self.package is not None:
            return f"package://{self.package}/{package_path(filename)}"
        if Path(filename).is_absolute():
            return filename
        target = os.path.abspath(self.base_dir / filename)
        if self.out_dir is None:
            return Path(target).as_posix()
        return Path(os.path.relpath(target, os.path.abspath(self.out_dir))).as_posix()


def package_path(filename: str) -> str:
    """Where a path-named mesh goes inside the description package: `meshes/<file name>`.

    The parent directory's name is kept when it is not `meshes` (visual/collision
    variants of one part usually share a file name), so distinct files stay distinct.
    """
    p = Path(filename)
    parent = p.parent.name
    sub = f"{parent}/" if parent and parent not in (MESH_DIR, ".", "..") else ""
    return f"{MESH_DIR}/{sub}{p.name}"


def spec_mesh_names(spec: RobotSpec) -> list[str]:
    """Every mesh and texture file name the spec uses, in order, once each."""
    out: list[str] = []
    links = [
        *spec.all_links().values(),
        *(lk for p in spec.parts.values() for lk in p.links.values()),
    ]
    for link in links:
        for shape in (*link.visuals(), *link.collisions()):
            if shape.geometry.mesh is not None:
                out.append(shape.geometry.mesh.filename)
            m = shape.material
            if m is not None and not isinstance(m, str) and m.texture is not None:
                out.append(m.texture)
    out += [m.texture for m in spec.materials.values() if m.texture is not None]
    return list(dict.fromkeys(out))


def package_of(filename: str) -> str | None:
    """The ROS package a `package://NAME/...` file name points into, else None."""
    parsed = urlparse(filename)
    if parsed.scheme != "package":
        return None
    return parsed.netloc or unquote(parsed.path).lstrip("/").partition("/")[0]


def package_meshes(spec: RobotSpec) -> dict[str, Path]:
    """Path in the description package -> the file, for every path-named mesh of the spec.

    Raises:
        InputError: a file is missing, or two different files would land on one path.
    """
    out: dict[str, Path] = {}
    for name in spec_mesh_names(spec):
        if not is_path(name):
            continue
        path = locate(name, spec.base_dir)
        rel = package_path(name)
        if rel in out and os.path.realpath(out[rel]) != os.path.realpath(path):
            raise InputError(
                f"meshes {out[rel]} and {path} would both be copied to {rel}: rename one",
                field="meshes",
            )
        out[rel] = path
    return out
