"""`armcli tree`: print the kinematic tree as text or Graphviz DOT."""

from __future__ import annotations

import io
import sys
from pathlib import Path

import typer

from armcli.commands.help_text import ROBOT_HELP
from armcli.commands.options import choice, spec_argument
from armcli.commands.xacro_inputs import (
    args_argument,
    env_option,
    package_dir_option,
    split_robot,
    write_notes,
    xacro_inputs,
)
from armcli.errors import InputError
from armcli.io import terminal
from armcli.io.files import write_file_atomic
from armcli.io.oneline import one_line
from armcli.io.outdir import check_output_file
from armcli.spec.discover import find_spec
from armcli.xacro.trust import TRUST_XACRO_HELP, UNSANDBOXED_HELP, trust_mode

TREE_FORMATS = ("text", "dot")


def tree_cmd(
    robot: Path | None = spec_argument(ROBOT_HELP),
    args: list[str] = args_argument(),
    fmt: str = choice(
        "text", TREE_FORMATS, "--format", help="text (a tree, the default) or dot (Graphviz)."
    ),
    out: Path = typer.Option(None, "-o", "--out", help="Write to this file instead of stdout."),
    package_dir: list[str] = package_dir_option(),
    env: list[str] = env_option(),
    trust_xacro: bool = typer.Option(False, "--trust-xacro", help=TRUST_XACRO_HELP),
    unsandboxed: bool = typer.Option(False, "--trust-xacro-unsandboxed", help=UNSANDBOXED_HELP),
) -> None:
    """Print the kinematic tree: links, and joints with their types and limits."""
    from armcli.urdf.tree import parse_tree, to_dot, to_rich  # on use: `--help` stays light
    from armcli.view.scene import load_robot

    if fmt not in TREE_FORMATS:
        raise InputError(f"unknown format {fmt!r}; known: text, dot", field="--format")
    if out is not None:
        check_output_file(out, "--out")
    robot, tokens = split_robot(robot, args)
    inputs = xacro_inputs(tokens, env, package_dir)
    src = load_robot(
        find_spec(robot), trust_mode(trust_xacro, unsandboxed), inputs.packages, inputs
    )
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
        sys.stdout.write(one_line(f"wrote {out}") + "\n")


def register(app: typer.Typer) -> None:
    """Add `armcli tree` to the app."""
    app.command("tree")(tree_cmd)
