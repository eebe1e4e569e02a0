"""`armcli import FILE`: read a URDF or xacro file, import it, write the spec atomically."""

from __future__ import annotations

import os
from pathlib import Path
from urllib.parse import unquote, urlparse

from armcli.errors import ExistingFileError, InputError
from armcli.importer.run import GainSource, ImportResult, import_urdf
from armcli.io.files import write_file_atomic
from armcli.io.mesh_confine import package_xml_name
from armcli.io.outdir import check_output_file
from armcli.io.packages import PackageLookup
from armcli.urdf.doc import Urdf
from armcli.urdf.source import Trust, read_urdf_file
from armcli.xacro.args import XacroInputs


def source_label(path: Path, inputs: XacroInputs | None) -> str:
    """How the spec names its source: the file, with the xacro arguments given."""
    args = dict(inputs.args) if inputs is not None else {}
    given = " ".join(f"{k}:={v}" for k, v in args.items())
    return path.as_posix() + (f" {given}" if given else "")


def mesh_packages(urdf: Urdf) -> list[str]:
    """The packages the document's `package://` meshes name, in order of first use."""
    names: dict[str, None] = {}
    for link in urdf.links:
        for shape in (*link.visuals, *link.collisions):
            g = shape.geometry
            uri = g.filename if g is not None and g.kind == "mesh" and g.filename else ""
            parsed = urlparse(uri)
            if parsed.scheme == "package":
                names[parsed.netloc or unquote(parsed.path).lstrip("/").partition("/")[0]] = None
    return list(names)


def import_file(
    path: Path,
    out: Path,
    *,
    inputs: XacroInputs | None = None,
    trust_xacro: Trust = False,
    arm_root: str | None = None,
    force: bool = False,
    gains: GainSource | None = None,
) -> tuple[ImportResult, tuple[str, ...]]:
    """Import `path` and write the spec to `out` (all or nothing; never over a file unless forced).

    Returns the result and the `note:` lines of a xacro expansion (arguments it used).

    Raises:
        ExistingFileError: `out` exists and `force` is not set (nothing was read or written).
        InputError: the file is unusable or holds what a spec cannot.
    """
    check_output_file(out, "out", [path], parents=True)  # never over the file it imports
    if out.exists() and not force:
        raise ExistingFileError(f"{out} exists; pass `force` to replace it", file=out)
    if out.is_dir():
        raise InputError("is a directory; give the spec file to write", file=out, field="out")
    urdf = read_urdf_file(path, trust_xacro=trust_xacro, inputs=inputs)
    lookup = inputs.packages if inputs is not None else PackageLookup()
    found = {n: lookup.find(n, path) for n in mesh_packages(urdf)}
    recorded = {n: p for n, p in found.items() if p is not None and package_xml_name(p) == n}
    notes = list(urdf.notes)
    for n, p in found.items():
        if n in recorded:
            continue
        where = f"{n}={os.path.relpath(p)}" if p is not None else f"{n}=PATH"
        notes.append(
            f"warning: package {n!r} (named by its meshes) "
            + ("has no package.xml to record" if p is not None else "was not found")
            + f": pass --package-dir {where} to check, view, render and ros-package"
        )
    result = import_urdf(
        urdf.text,
        source_label(path, inputs),
        out,
        arm_root=arm_root,
        source_dir=path.parent,
        gains=gains,
        packages=recorded,
    )
    write_file_atomic(out, result.text)
    return result, tuple(notes)
