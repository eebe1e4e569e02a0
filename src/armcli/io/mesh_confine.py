"""Mesh files armcli hands to Pinocchio, coal and trimesh: resolved, confined and bounded.

Pinocchio resolves `package://` URIs itself by appending the URI path to every
search directory it is given, which reaches paths armcli never checked (a
symlink `pkg/etc/pkg -> /` turns `package://pkg/etc/passwd` into /etc/passwd).
So armcli resolves each mesh URI itself (urdf/meshes.py `resolve`), follows
symlinks, requires the real path to be inside the allowed roots, and then
rewrites the URDF so that every mesh filename is that absolute real path
(urdf/meshes.py `confined_mesh_xml`, with this module's bounds); Pinocchio gets
no search directories at all. A package root found by walking
up from the URDF only counts when its package.xml names the package, so that
any parent folder's name does not become a root. Mesh files are regular files
under a size cap, and the total per robot is capped too.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.errors import InputError
from armcli.io.meshbound import check_mesh_payload
from armcli.io.userfile import check_regular, read_regular

MAX_MESH_BYTES = 20_000_000  # one mesh file; a 50 MB STL took 51 s and 1.6 GB to render
MAX_MESH_TOTAL_BYTES = 100_000_000  # all mesh files of one robot
MAX_PACKAGE_XML_BYTES = 1_000_000

if TYPE_CHECKING:
    from lxml import etree


def _safe_xml() -> etree.XMLParser:
    """A parser without entities, DTDs or network access.

    lxml is imported on use: package lookup sits on every command's path, `--help` included.
    """
    from lxml import etree

    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False)


def package_xml_name(directory: Path) -> str | None:
    """The <name> in `directory`/package.xml, or None when there is no readable one."""
    path = directory / "package.xml"
    if not path.is_file():
        return None
    from lxml import etree

    try:
        root = etree.fromstring(read_regular(path, max_bytes=MAX_PACKAGE_XML_BYTES), _safe_xml())
    except (InputError, etree.XMLSyntaxError):
        return None
    name = root.findtext("name") if root is not None else None
    return name.strip() if name else None


def is_package(directory: Path, name: str) -> bool:
    """Whether `directory` is the ROS package `name`.

    Either its package.xml says so, or it is an installed ROS 2 package: `<prefix>/share/NAME`
    registered in the ament index (`<prefix>/share/ament_index/resource_index/packages/NAME`),
    which is how `package://NAME` resolves in ROS 2 even when package.xml names it otherwise
    (example-robot-data's says example_robot_descriptions).
    """
    if package_xml_name(directory) == name:
        return True
    share = directory.parent
    marker = share / "ament_index" / "resource_index" / "packages" / name
    return directory.name == name and share.name == "share" and marker.is_file()


def bounded_mesh_file(path: Path, source: str) -> Path:
    """The symlink-free path of a (confined) mesh file, checked to be a bounded regular file."""
    real = Path(os.path.realpath(path))
    size = check_regular(real, "mesh file")
    if size > MAX_MESH_BYTES:
        raise InputError(
            f"mesh {real} is {size} bytes, more than the {MAX_MESH_BYTES}-byte cap per mesh",
            file=source,
        )
    try:  # compressed meshes inflated under a cap, declared triangles counted (issue 27)
        check_mesh_payload(real, MAX_MESH_BYTES)
    except InputError as exc:
        raise InputError(exc.message, file=source) from None
    return real


def check_total(paths: Iterable[Path], source: str) -> None:
    """Refuse a robot whose distinct mesh files add up to more than MAX_MESH_TOTAL_BYTES."""
    total = sum(os.stat(p).st_size for p in set(paths))
    if total > MAX_MESH_TOTAL_BYTES:
        raise InputError(
            f"the robot's meshes are {total} bytes, more than the {MAX_MESH_TOTAL_BYTES}-byte cap",
            file=source,
        )
