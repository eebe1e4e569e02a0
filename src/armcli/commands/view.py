"""`armcli view`, `armcli render`, `armcli tree`: see the robot from a spec or a URDF.

A spec is built in memory (xacro expansion, nothing written); a URDF is read
strictly; a foreign xacro file only with --trust-xacro (see robot_source).
Heavy libraries (viser, yourdfpy, matplotlib) load inside the commands.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.defaults import DEFAULT_SPEC
from armcli.errors import InputError
from armcli.robot_source import TRUST_XACRO_HELP

if TYPE_CHECKING:
    from armcli.render import Tool

ROBOT_HELP = "Robot spec YAML, URDF file, or xacro file (with --trust-xacro)."


@dataclass(frozen=True)
class RobotSource:
    """A robot to show: URDF text plus what a spec adds (named poses, tool point)."""

    xml: str
    source: str
    name: str
    mesh_dir: Path | None
    joints: tuple[str, ...]  # the joints `--q a,b,...` assigns, in order
    poses: dict[str, dict[str, float]] = field(default_factory=dict)
    tool: Tool | None = None


def load_robot(path: Path, trust_xacro: bool = False) -> RobotSource:
    """Spec YAML (built in memory), URDF or trusted xacro file -> RobotSource.

    Mesh URIs must resolve inside robot_source.allowed_roots.
    """
    from armcli.render import Tool
    from armcli.robot_source import read_robot, urdf_text

    robot = read_robot(path, trust_xacro=trust_xacro)
    spec = robot.spec
    if spec is not None:
        tool = Tool(spec.arm.tool.link, spec.arm.tool.xyz) if spec.arm.tool else None
        return RobotSource(
            xml=urdf_text(robot.robot),
            source=str(path),
            name=spec.name,
            mesh_dir=None,
            joints=tuple(spec.movable_arm_joints()),
            poses={p: spec.pose(p) for p in spec.poses},
            tool=tool,
        )
    from armcli.tree import tree_from_urdf

    urdf = robot.robot
    tree = tree_from_urdf(urdf)
    movable = tree.movable()
    tip = max((d, j.child) for d, j in tree.walk())[1] if tree.joints else tree.root
    return RobotSource(
        xml=urdf_text(urdf),
        source=str(path),
        name=tree.robot or path.stem,
        mesh_dir=path.parent,
        joints=tuple(j.name for j in movable),
        tool=Tool(tip),
    )


def parse_q(text: str, robot: RobotSource) -> dict[str, float]:
    """`0.3,pi/4` (in robot.joints order) or `joint=0.3,other=pi/4` -> {joint: value}."""
    from armcli.expr import eval_expr

    items = [s.strip() for s in text.split(",") if s.strip()]
    out: dict[str, float] = {}
    try:
        if items and all("=" in s for s in items):
            for s in items:
                name, value = s.split("=", 1)
                out[name.strip()] = float(eval_expr(value.strip()))
            return out
        if len(items) != len(robot.joints):
            order = ", ".join(robot.joints) or "(none)"
            raise InputError(f"expected {len(robot.joints)} values, for: {order}", field="--q")
        return {j: float(eval_expr(s)) for j, s in zip(robot.joints, items, strict=True)}
    except InputError as exc:
        raise InputError(exc.message, field="--q") from None
    except (ValueError, ArithmeticError) as exc:
        raise InputError(f"{text!r}: {exc}", field="--q") from None


def _pose_q(robot: RobotSource, pose: str | None, q: str | None) -> dict[str, float]:
    if pose is not None and q is not None:
        raise InputError("give --pose or --q, not both", field="--pose")
    if pose is not None:
        if pose not in robot.poses:
            known = ", ".join(robot.poses) or "(none: a URDF has no named poses)"
            raise InputError(f"unknown pose {pose!r}; known: {known}", field="--pose")
        return dict(robot.poses[pose])
    return parse_q(q, robot) if q is not None else {}


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise InputError(f"{text!r}: expected WIDTHxHEIGHT in pixels", field="--size") from None
    if not (100 <= w <= 8000 and 100 <= h <= 8000):
        raise InputError(f"{text!r}: each side must be 100..8000 px", field="--size")
    return w, h


def render_cmd(
    robot: Path = typer.Argument(DEFAULT_SPEC, help=ROBOT_HELP),
    pose: str = typer.Option(None, "--pose", help="A named pose of the spec."),
    q: str = typer.Option(
        None,
        "--q",
        help="Joint values in rad (m if prismatic): '0.3,pi/4' in arm order, or 'joint=0.3,...'.",
    ),
    out: Path = typer.Option(Path("robot.png"), "-o", "--out", help="PNG to write."),
    size: str = typer.Option("1200x600", "--size", help="Image size WIDTHxHEIGHT in pixels."),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
) -> None:
    """Draw the robot at a pose from two viewpoints into a PNG (headless, no GPU)."""
    from armcli.outdir import check_output_file
    from armcli.render import load_urdf, render_png

    check_output_file(out, "--out")
    src = load_robot(robot, trust_xacro)
    values = _pose_q(src, pose, q)
    width, height = _size(size)
    urdf = load_urdf(src.xml, src.source, src.mesh_dir)
    res = render_png(
        urdf,
        values,
        out,
        tool=src.tool,
        name=src.name,
        size=(width, height),
        field="--pose" if pose else "--q",
    )
    tip = (
        ""
        if res.tool_position is None
        else " tool at ({:.3f}, {:.3f}, {:.3f}) m".format(*res.tool_position)
    )
    sys.stdout.write(f"wrote {res.path} ({res.width}x{res.height} px){tip}\n")


def tree_cmd(
    robot: Path = typer.Argument(DEFAULT_SPEC, help=ROBOT_HELP),
    fmt: str = typer.Option("text", "--format", help="text (a tree) or dot (Graphviz)."),
    out: Path = typer.Option(None, "-o", "--out", help="Write to this file instead of stdout."),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
) -> None:
    """Print the kinematic tree: links, and joints with their types and limits."""
    from armcli.tree import parse_tree, to_dot, to_rich

    if fmt not in ("text", "dot"):
        raise InputError(f"unknown format {fmt!r}; known: text, dot", field="--format")
    if out is not None:
        from armcli.outdir import check_output_file

        check_output_file(out, "--out")
    src = load_robot(robot, trust_xacro)
    tree = parse_tree(src.xml, src.source)
    if fmt == "dot":
        text = to_dot(tree)
    else:
        import io

        from rich.console import Console

        if out is None:
            Console().print(to_rich(tree))
            return
        buf = io.StringIO()
        Console(file=buf, width=120).print(to_rich(tree))
        text = buf.getvalue()
    if out is None:
        sys.stdout.write(text)
    else:
        from armcli.fsio import write_file_atomic

        write_file_atomic(out, text.encode("utf-8"))
        sys.stdout.write(f"wrote {out}\n")


def view_cmd(
    robot: Path = typer.Argument(DEFAULT_SPEC, help=ROBOT_HELP),
    replay: Path = typer.Option(None, "--replay", help="A CSV written by `armcli simulate`."),
    pose: str = typer.Option(None, "--pose", help="Start at this named pose."),
    host: str = typer.Option("127.0.0.1", "--host", help="Address to listen on."),
    port: int = typer.Option(8080, "--port", help="Port to listen on (0: any free port)."),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
) -> None:
    """Open a browser 3-D viewer with joint sliders, named poses and simulation replay."""
    from armcli.render import joint_limits, load_urdf
    from armcli.replay import load_replay
    from armcli.viewer import Viewer

    src = load_robot(robot, trust_xacro)
    _pose_q(src, pose, None)  # validate before starting the server
    if not 0 <= port <= 65535:
        raise InputError(f"{port} is not a port number", field="--port")
    run = None
    if replay is not None:
        names = list(joint_limits(load_urdf(src.xml, src.source, src.mesh_dir)))
        run = load_replay(replay, names)
    viewer = Viewer(
        src.xml,
        name=src.name,
        source=src.source,
        mesh_dir=src.mesh_dir,
        poses=src.poses,
        tool=src.tool,
        replay=run,
        host=host,
        port=port,
    )
    try:  # entered before the URL is printed, so an early Ctrl-C still stops cleanly
        if pose:
            viewer.apply_pose(pose)
        sys.stdout.write(f"armcli view: {src.name} at {viewer.url}  (Ctrl-C to stop)\n")
        sys.stdout.flush()
        viewer.serve_forever()
    except KeyboardInterrupt:
        sys.stdout.write("viewer stopped\n")
    finally:
        viewer.close()


def register(app: typer.Typer) -> None:
    app.command("view")(view_cmd)
    app.command("render")(render_cmd)
    app.command("tree")(tree_cmd)
