"""`armcli tree`: print the kinematic tree as text or Graphviz DOT."""

from __future__ import annotations

import io
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from armcli.commands.options import choice
from armcli.commands.robot_input import robot_options, write_notes
from armcli.io import terminal
from armcli.io.files import write_file_atomic
from armcli.io.outdir import check_output_file, existing, wrote
from armcli.io.terminal import say_line

if TYPE_CHECKING:
    from armcli.urdf.source import RobotInput

TREE_FORMATS = ("text", "dot")


@robot_options()
def tree_cmd(
    robot: RobotInput,
    fmt: str = choice(
        "text", TREE_FORMATS, "--format", help="text (a tree, the default) or dot (Graphviz)."
    ),
    out: Path = typer.Option(None, "-o", "--out", help="Write to this file instead of stdout."),
) -> None:
    """Print the kinematic tree: links, and joints with their types and limits."""
    from armcli.urdf.tree import parse_tree, to_dot, to_rich  # on use: `--help` stays light
    from armcli.view.scene import load_robot

    if out is not None:
        check_output_file(out, "--out", robot.files())  # never over the robot file
    before = existing(out)
    src = load_robot(robot)
    write_notes(src.notes)
    tree = parse_tree(src.xml, src.source)
    if fmt == "dot":
        text = to_dot(tree)
    else:
        if out is None:
            terminal.console().print(to_rich(tree), crop=False)
            return
        buf = io.StringIO()
        terminal.console(buf, terminal.UNBOUNDED).print(to_rich(tree), crop=False)
        text = buf.getvalue()
    if out is None:
        sys.stdout.write(text)
    else:
        write_file_atomic(out, text.encode("utf-8"))
        say_line(wrote(out, out in before))


def register(app: typer.Typer) -> None:
    """Add `armcli tree` to the app."""
    app.command("tree")(tree_cmd)
