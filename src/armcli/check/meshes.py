"""Rule `mesh-missing`: every mesh URI must resolve to a file inside the allowed roots.

Resolution itself is armcli.urdf.meshes, shared with `view` and `render`.
"""

from __future__ import annotations

from pathlib import Path

from armcli.check.findings import Collector
from armcli.check.options import CheckOptions
from armcli.urdf.doc import Urdf
from armcli.urdf.meshes import confined, mesh_hint, resolve


def check(urdf: Urdf, opts: CheckOptions, out: Collector) -> None:
    """Rule `mesh-missing`: meshes without a filename, outside the allowed roots, or absent.

    Each URI is reported once; a path outside the allowed roots is never stat'ed.
    """
    base = Path(urdf.source).parent
    search = opts.mesh_search()
    reported: set[str] = set()
    for link in urdf.links:
        for s in (*link.visuals, *link.collisions):
            g = s.geometry
            if g is None or g.kind != "mesh" or g.filename in reported:
                continue
            if not g.filename:
                out.add("mesh-missing", g.line, f"link {link.name!r}: mesh without a filename")
                continue
            path = resolve(g.filename, base, search)
            if path is not None and not confined(g.filename, path, base, search):  # not stat'ed
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
                why = (
                    f"unknown package; {mesh_hint(g.filename)}"
                    if path is None
                    else f"no file {path}"
                )
                out.add(
                    "mesh-missing",
                    g.line,
                    f"link {link.name!r}: mesh {g.filename!r}: {why}",
                    uri=g.filename,
                )
