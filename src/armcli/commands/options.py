"""Option builders shared by the commands, so every `--help` reads the same way.

Typer's own choice handling prints click's message (with a stray "env var: None" under
click 8.2); `choice` lists the values in `--help` as `[a|b]` and refuses anything else
with armcli's one-line error naming the option (exit 2).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import typer

from armcli.defaults import SEED_LIMIT
from armcli.errors import InputError


def choice(default: str | None, choices: Sequence[str], *names: str, help: str) -> Any:
    """A string option restricted to `choices`; the default is stated in `help` (None: unset)."""

    def check(value: str | None) -> str | None:
        if value is None and default is None:
            return None
        if value not in choices:
            raise InputError(
                f"unknown value {value!r}; valid: {', '.join(choices)}", field=names[0]
            )
        return value

    return typer.Option(
        default,
        *names,
        metavar="[" + "|".join(choices) + "]",
        show_default=False,
        callback=check,
        help=help,
    )


def out_option(default: Path, help: str) -> Any:
    """`-o/--out`, with its default stated in the help text."""
    return typer.Option(
        default, "-o", "--out", show_default=False, help=f"{help} (default: {default})."
    )


def option(default: Any, *names: str, help: str, **kwargs: Any) -> Any:
    """A typer option whose default, when set, is stated in the help text (not as `[default:]`)."""
    unset = (  # `...`: a required option (typer's spelling), which has no default to state
        default is None
        or default is False
        or default is ...
        or (isinstance(default, list | tuple) and not default)
    )
    text = help if unset else f"{help} (default: {default})."
    return typer.Option(default, *names, show_default=False, help=text, **kwargs)


def seed_option(help: str) -> Any:
    """`--seed`, refused where click parses it unless 0 <= seed < 2**32 (issue 42)."""

    def check(value: int) -> int:
        if not 0 <= value < SEED_LIMIT:
            raise InputError(
                f"must be an integer from 0 to {SEED_LIMIT - 1} (0 <= seed < 2**32), got {value}",
                field="--seed",
            )
        return value

    return option(0, "--seed", callback=check, metavar="0..2**32-1", help=help)
