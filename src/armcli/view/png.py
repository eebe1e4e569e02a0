"""Static pictures of a robot at a pose, drawn headless with matplotlib (no GPU, no display).

yourdfpy turns the URDF into a trimesh scene (boxes, cylinders, spheres and any
meshes, coloured from the URDF materials) and poses it by forward kinematics;
matplotlib's Agg backend draws the triangles, Lambert-shaded, from two
viewpoints with equal axes in metres. Large faces are subdivided so that
matplotlib's per-face depth sort (a painter's algorithm) stays right.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import InputError
from armcli.io.files import write_file_atomic
from armcli.io.mesh_confine import bounded_mesh_file, check_total
from armcli.robot.joints import rest
from armcli.robot.jointvalues import snap_to_limits
from armcli.robot.tool import ToolPoint
from armcli.spec.joint_types import position_bounds
from armcli.urdf.meshes import MeshSearch, confined, resolve
from armcli.urdf.meshlog import MeshLog, quiet_trimesh
from armcli.urdf.read import parse_root

MAX_EDGE = 0.04  # [m] faces are split to this edge length so depth sorting works
SPLIT_ROUNDS = 8  # halvings at most; longer edges stay longer than MAX_EDGE
MAX_RENDER_TRIANGLES = 2_000_000  # after splitting: ~1 GB of matplotlib polygons
LIGHT = np.array([0.35, -0.55, 0.76])  # direction towards the light, world frame
AMBIENT = 0.3  # share of colour that does not depend on the light
VIEWS = (  # (title, elevation [deg], azimuth [deg])
    ("3-D view", 22.0, -58.0),
    ("side view (x-z plane)", 0.0, -90.0),
)
DEFAULT_SIZE = (1200, 600)  # [px]
DPI = 100


@dataclass(frozen=True)
class RenderResult:
    """What `render_png` drew: the file, its size [px], the pose and the tool point [m]."""

    path: Path
    width: int
    height: int
    q: dict[str, float]
    tool_position: tuple[float, float, float] | None


MESH_HINT = "--package-dir NAME=PATH points package://NAME at a folder"
FALLBACK_RGBA = (0.6, 0.6, 0.6, 1.0)  # meshes whose colour cannot be read
TITLE_WIDTH = 110  # [characters] per title line, so many joints do not run off the figure
TITLE_LINES = 4  # of joint values at most: PR2's 40-odd joints end in "... and N more"
TITLE_FONT = 10  # [pt]
LINE_SPACING = 1.4  # text line height / font size (matplotlib's default 1.2, plus leading)
VIEW_TITLE_SPACE = 0.45  # [in] the views' own titles above their axes


def _mesh_handler(
    base: Path,
    where: MeshSearch,
    source: str,
    skipped: dict[str, str] | None,
    said: MeshLog | None = None,
) -> Callable[[str], str]:
    """Yourdfpy's filename handler: armcli's resolver, confinement and size caps.

    A mesh that is missing, or outside the allowed roots (never read), is recorded in
    `skipped` (URI -> why) when given, else an InputError.
    """
    loaded: set[Path] = set()

    def resolve_mesh(fname: str) -> str:
        if said is not None:
            said.current = fname  # trimesh loads this file next: its complaints are about it
        path = resolve(fname, base, where)
        why = None
        if path is not None and not confined(fname, path, base, where):  # never read
            why = (
                f"resolves to {path}, outside the allowed directories (the URDF's directory "
                "and ROS package, --package-dir, ROS_PACKAGE_PATH, packages found)"
            )
        elif path is None or not path.is_file():
            why = "not found"
        if why is not None or path is None:
            why = why or "not found"
            if skipped is None:
                raise InputError(f"mesh {fname!r} {why}", file=source)
            skipped[fname] = why
            return ""  # nothing: yourdfpy skips it (the URI itself could name a file in cwd)
        real = bounded_mesh_file(path, source)  # trimesh opens the checked real path
        loaded.add(real)
        check_total(loaded, source)
        return str(real)

    return resolve_mesh


def load_urdf(
    xml: str,
    source: str = "<urdf>",
    mesh_dir: str | Path | None = None,
    search: MeshSearch | None = None,
    skipped: dict[str, str] | None = None,
    mesh_notes: dict[str, str] | None = None,
) -> Any:
    """URDF text -> yourdfpy.URDF with its visual scene.

    Meshes resolve with armcli.urdf.meshes from `mesh_dir` (the URDF's directory), as in
    `check`, honouring `--package-dir` through `search`. The text first passes the strict
    URDF reader (no DTDs or entities, bounded size and depth), since yourdfpy's own lxml
    parser would resolve entities. A mesh file that cannot be found, or lies outside the
    allowed directories (never read), is an InputError where yourdfpy would log and draw
    nothing, unless the caller passes a `skipped` dict: then URI -> why is recorded there
    and the rest is drawn (render warns). What trimesh said while loading a mesh (a
    missing texture image: the mesh is drawn in its plain colour) goes to `mesh_notes`
    (URI -> message) when given, and never to stderr.
    """
    parse_root(xml.encode("utf-8"), source)
    base = Path(mesh_dir or ".")
    absent: dict[str, str] = {}
    with quiet_trimesh() as said:
        resolve_mesh = _mesh_handler(base, search or MeshSearch(), source, absent, said)
        urdf = _load(xml, source, resolve_mesh)
    if mesh_notes is not None:
        mesh_notes.update(said.said)

    if skipped is not None:
        skipped.update(absent)
    elif absent:
        uri, why = next(iter(absent.items()))
        if why != "not found":
            raise InputError(f"mesh {uri!r} {why}", file=source)
        raise InputError(
            f"mesh file not found: {uri} (searched from {base}; {MESH_HINT})", file=source
        )
    return urdf


def _load(xml: str, source: str, resolve_mesh: Callable[[str], str]) -> Any:
    """yourdfpy.URDF.load with its visual meshes; its warnings become our errors."""
    import logging

    import yourdfpy

    log = logging.getLogger("yourdfpy")
    level, log.level = log.level, logging.CRITICAL  # its warnings become our error above
    try:
        return yourdfpy.URDF.load(
            io.BytesIO(xml.encode("utf-8")),
            build_collision_scene_graph=False,
            load_collision_meshes=False,
            filename_handler=resolve_mesh,
        )
    except InputError:
        raise
    except Exception as exc:  # yourdfpy raises assorted types for bad URDFs
        raise InputError(f"cannot load this URDF: {exc}", file=source) from None
    finally:
        log.level = level


def joint_limits(urdf: Any) -> dict[str, tuple[float, float] | None]:
    """Movable joints in yourdfpy's order -> (lower, upper), None for unlimited joints."""
    out: dict[str, tuple[float, float] | None] = {}
    for name, joint in zip(urdf.actuated_joint_names, urdf.actuated_joints, strict=True):
        out[name] = position_bounds(joint.type, joint.limit)
    return out


def snapped(urdf: Any, q: Mapping[str, float]) -> tuple[dict[str, float], list[str]]:
    """`q` with values a hair beyond a limit set onto it (robot.jointvalues.SNAP), and notes."""
    limits = {name: lim for name, lim in joint_limits(urdf).items() if lim is not None}
    return snap_to_limits(q, limits)


def full_configuration(
    urdf: Any, q: Mapping[str, float], source: str | None = None, field: str | None = None
) -> dict[str, float]:
    """Every movable joint's value (`neutral` where `q` is silent).

    Unknown joints and values outside the limits raise InputError naming `field`.
    """
    limits = joint_limits(urdf)
    for name, value in q.items():
        if name not in limits:
            known = ", ".join(limits) or "(none)"
            raise InputError(
                f"unknown movable joint {name!r}; known: {known}", file=source, field=field
            )
        lim = limits[name]
        if not np.isfinite(value) or (lim and not lim[0] - 1e-9 <= value <= lim[1] + 1e-9):
            raise InputError(
                f"joint {name!r}: {value:g} is outside its limits [{lim[0]:g}, {lim[1]:g}]"
                if lim
                else f"joint {name!r}: {value!r} is not a finite number",
                file=source,
                field=field,
            )
    return {name: float(q.get(name, neutral(limits[name]))) for name in limits}


def neutral(limit: tuple[float, float] | None) -> float:
    """The value a joint takes when nobody sets it: its rest (`robot.joints.rest`)."""
    return 0.0 if limit is None else rest(*limit)


def tool_position(urdf: Any, tool: ToolPoint | None) -> np.ndarray | None:
    """The tool point in the root-link frame [m] at the URDF's current configuration."""
    if tool is None:
        return None
    T = urdf.get_transform(tool.link, urdf.base_link)
    return np.asarray(T[:3, :3] @ np.asarray(tool.xyz) + T[:3, 3])


def _mesh_rgba(mesh: Any) -> np.ndarray:
    """One RGBA row in [0, 1] for a mesh: its colour, a texture's main colour, or grey."""
    visual = mesh.visual
    try:
        if getattr(visual, "kind", None) == "texture" or not hasattr(visual, "face_colors"):
            main = visual.material.main_color  # textured meshes (e.g. COLLADA with images)
            return np.asarray(main, dtype=float).reshape(1, -1)[:, :4] / 255.0
        return np.asarray(visual.face_colors, dtype=float)[:1] / 255.0
    except (AttributeError, TypeError, ValueError, IndexError):
        return np.array([FALLBACK_RGBA])


def _split_for_sorting(mesh: Any) -> Any:
    """Faces split to about MAX_EDGE, coarser for large shapes so at most 2**SPLIT_ROUNDS per edge.

    A fixed MAX_EDGE made trimesh give up ("max_iter exceeded") on a 10 m box.
    """
    size = float(np.linalg.norm(mesh.extents))
    if not size > MAX_EDGE:
        return mesh
    edge = max(MAX_EDGE, size / 2 ** (SPLIT_ROUNDS - 1))
    return mesh.subdivide_to_size(edge, max_iter=SPLIT_ROUNDS)


def posed_triangles(urdf: Any, q: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """World-frame triangles (n, 3, 3) [m] and their shaded RGBA colours (n, 4) at pose q."""
    urdf.update_cfg(dict(q))
    tris, cols = [], []
    n_faces = 0
    for mesh in urdf.scene.dump():
        rgba = _mesh_rgba(mesh)
        mesh = _split_for_sorting(mesh)
        n_faces += len(mesh.faces)
        if n_faces > MAX_RENDER_TRIANGLES:
            raise InputError(
                f"more than {MAX_RENDER_TRIANGLES:,} triangles to draw; armcli's render bound "
                "(simplify the visual meshes)",
            )
        normals = np.asarray(mesh.face_normals)
        light = AMBIENT + (1 - AMBIENT) * np.clip(normals @ (LIGHT / np.linalg.norm(LIGHT)), 0, 1)
        c = np.repeat(rgba, len(mesh.faces), axis=0)
        c[:, :3] *= light[:, None]
        tris.append(np.asarray(mesh.triangles))
        cols.append(c)
    if not tris:
        return np.zeros((0, 3, 3)), np.zeros((0, 4))
    return np.concatenate(tris), np.concatenate(cols)


def _draw_view(
    ax: Any, tris: np.ndarray, cols: np.ndarray, tip: np.ndarray | None, extent: np.ndarray
) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax.add_collection3d(Poly3DCollection(tris, facecolors=cols, edgecolors=cols, linewidths=0.3))
    pts = np.concatenate([tris.reshape(-1, 3), extent])
    pts = pts if len(pts) else np.zeros((1, 3))
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 0.05) * 1.05
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1), zoom=1.1)
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(5))
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    if tip is not None:
        ax.scatter(*tip, color="black", s=18, depthshade=False, zorder=10)


def _title(name: str, q: Mapping[str, float], urdf: Any, tip: np.ndarray | None) -> str:
    """Name, joint values (continuous joints such as wheels only when turned) and tool point."""
    limits = joint_limits(urdf)
    shown = {j: v for j, v in q.items() if v != 0.0 or limits.get(j) is not None} or q
    unit = {j: "m" if urdf.joint_map[j].type == "prismatic" else "rad" for j in shown}
    entries = [f"{j} = {v:.3f} {unit[j]}" for j, v in shown.items()]
    rows = textwrap.wrap(f"{name}: {', '.join(entries) or 'no movable joints'}", TITLE_WIDTH)
    k = len(entries)
    while len(rows) > TITLE_LINES and k > 0:  # more would run into the views (PR2, G1)
        k -= 1
        more = f" ... and {len(entries) - k} more joint(s)"
        rows = textwrap.wrap(f"{name}: {', '.join(entries[:k])}{more}", TITLE_WIDTH)
    text = "\n".join(rows)
    if tip is not None:
        text += "\ntool at ({:.3f}, {:.3f}, {:.3f}) m".format(*tip)
    return text


def render_figure(
    urdf: Any,
    q: Mapping[str, float],
    *,
    tool: ToolPoint | None = None,
    name: str = "robot",
    size: Sequence[int] = DEFAULT_SIZE,
    overlay: Callable[[Any], None] | None = None,
    extent: np.ndarray | None = None,
) -> Any:
    """A matplotlib Figure (Agg, not pyplot) of the robot at `q` from the two VIEWS.

    `overlay(ax)` draws more on each view (view.reach: the reachable region); `extent`
    (n, 3) [m] are more points the views' limits must include.
    """
    from matplotlib.figure import Figure

    tris, cols = posed_triangles(urdf, q)
    tip = tool_position(urdf, tool)
    fig = Figure(figsize=(size[0] / DPI, size[1] / DPI), dpi=DPI)
    for i, (title, elev, azim) in enumerate(VIEWS):
        ax = fig.add_subplot(1, len(VIEWS), i + 1, projection="3d", proj_type="ortho")
        ax.view_init(elev=elev, azim=azim)
        _draw_view(ax, tris, cols, tip, np.zeros((0, 3)) if extent is None else extent)
        if overlay is not None:
            overlay(ax)
        if elev == 0.0:  # looking along y: its ticks would collapse onto one spot
            ax.set_yticks([])
            ax.set_ylabel("")
        ax.set_title(title, fontsize=10)
    title = _title(name, q, urdf, tip)
    fig.suptitle(title, fontsize=TITLE_FONT, y=0.99, va="top")
    # The views start below the title's lines and their own titles (a fixed top let a long
    # title overprint them: PR2, G1).
    height = size[1] / DPI  # [in]
    used = (title.count("\n") + 1) * TITLE_FONT * LINE_SPACING / 72.0 + VIEW_TITLE_SPACE
    top = max(0.3, min(0.86, 0.99 - used / height))
    fig.subplots_adjust(left=0.02, right=0.96, bottom=0.04, top=top, wspace=0.12)
    return fig


def render_png(
    urdf: Any,
    q: Mapping[str, float],
    out: str | Path,
    *,
    tool: ToolPoint | None = None,
    name: str = "robot",
    size: Sequence[int] = DEFAULT_SIZE,
    field: str | None = None,
) -> RenderResult:
    """Draw the robot at `q` (validated against the limits) and write a PNG atomically.

    `field` names the user option `q` came from, for error messages.
    """
    full = full_configuration(urdf, q, field=field)
    fig = render_figure(urdf, full, tool=tool, name=name, size=size)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    path = write_file_atomic(out, buf.getvalue())
    tip = tool_position(urdf, tool)
    return RenderResult(
        path=Path(path),
        width=int(size[0]),
        height=int(size[1]),
        q=full,
        tool_position=None if tip is None else (float(tip[0]), float(tip[1]), float(tip[2])),
    )
