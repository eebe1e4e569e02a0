"""What a xacro expansion takes from the user, and the report of what it used.

xacro's command line is `xacro FILE NAME:=VALUE ...`; armcli takes the same
`NAME:=VALUE` tokens after the robot file on every command that reads xacro, plus
`--env VAR=VALUE` for `$(env VAR)` / `$(optenv VAR default)`: the expansion never
reads armcli's own environment (a CI runner's or a shell's variables would silently
change the robot), so `$(optenv)` takes its default unless the variable is passed
with --env, and `$(env)` without --env is an error naming the option.
The package lookup (`$(find)`, `package://`) travels with them.

`Expansion` is what came back: every argument with its value, which were given and
which took the file's default, variables that took their `$(optenv)` default, and the
expansion's warnings (duplicate YAML keys, the xacro library's `warning(...)`), as note lines that
every command prints the same way.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from armcli.errors import InputError
from armcli.io.packages import PackageLookup

ARG_SEPARATOR = ":="
ARGS_HELP = (
    "xacro arguments NAME:=VALUE after the robot file, as on xacro's command line "
    "(a xacro file only)."
)
ENV_HELP = (
    "VAR=VALUE seen by $(env VAR) and $(optenv VAR default) in a xacro file (repeatable); "
    "armcli's own environment is never read, so $(optenv) takes its default otherwise."
)
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
MAX_LISTED = 8  # names listed per note line before "... and N more"


@dataclass(frozen=True)
class XacroInputs:
    """Arguments, environment and package lookup for one xacro expansion."""

    args: Mapping[str, str] = field(default_factory=dict)  # NAME:=VALUE
    env: Mapping[str, str] = field(default_factory=dict)  # --env VAR=VALUE
    packages: PackageLookup = field(default_factory=PackageLookup)


def is_arg(token: str) -> bool:
    """Whether a command-line token is a xacro `NAME:=VALUE` argument (as xacro decides)."""
    return ARG_SEPARATOR in token


def parse_args(tokens: Iterable[str]) -> dict[str, str]:
    """`NAME:=VALUE` tokens -> {NAME: VALUE}; InputError naming a malformed one."""
    out: dict[str, str] = {}
    for token in tokens:
        name, _, value = token.partition(ARG_SEPARATOR)
        if not _NAME.match(name):
            raise InputError(
                f"{token!r}: expected NAME:=VALUE with NAME a xacro argument name",
                field="NAME:=VALUE",
            )
        out[name] = value
    return out


def parse_env(values: Iterable[str]) -> dict[str, str]:
    """`--env VAR=VALUE` options -> {VAR: VALUE}; InputError on a malformed one."""
    out: dict[str, str] = {}
    for v in values:
        name, sep, value = v.partition("=")
        if not sep or not _NAME.match(name):
            raise InputError(f"expected VAR=VALUE, got {v!r}", field="--env")
        out[name] = value
    return out


@dataclass(frozen=True)
class Expansion:
    """What one expansion used: arguments, environment defaults and warnings."""

    args: Mapping[str, str] = field(default_factory=dict)  # every argument's final value
    given: tuple[str, ...] = ()  # passed as NAME:=VALUE
    unused: tuple[str, ...] = ()  # given, but the file neither declares nor reads them
    optenv_defaults: tuple[str, ...] = ()  # $(optenv VAR ...) that took their default
    warnings: tuple[str, ...] = ()
    source_map: str = ""  # xacro.lines.source_map: where each expanded element was written

    @property
    def defaults(self) -> tuple[str, ...]:
        """The arguments that took the file's default (`<xacro:arg default=...>`)."""
        return tuple(n for n in self.args if n not in self.given)

    def notes(self) -> tuple[str, ...]:
        """Labelled lines (`note: ...`, `warning: ...`) saying what the expansion used.

        Arguments given and defaulted, unused ones, environment defaults, then warnings.
        """
        lines = []
        if self.args or self.given:
            given = _listed(f"{n}:={self.args.get(n, '')}" for n in self.given) or "none"
            defaults = _listed(f"{n}:={self.args[n]}" for n in self.defaults) or "none"
            lines.append(f"note: xacro arguments: given {given}; defaults taken {defaults}")
        if self.unused:
            lines.append(
                "warning: xacro arguments the file neither declares nor uses: "
                + ", ".join(self.unused)
            )
        if self.optenv_defaults:
            lines.append(
                f"note: $(optenv) took its default for {_listed(self.optenv_defaults)} "
                "(set one with --env VAR=VALUE)"
            )
        return (*lines, *(f"warning: {w}" for w in self.warnings))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-able form (from the expansion's child process)."""
        return {
            "args": dict(self.args),
            "given": list(self.given),
            "unused": list(self.unused),
            "optenv_defaults": list(self.optenv_defaults),
            "warnings": list(self.warnings),
            "source_map": self.source_map,
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Expansion:
        """The inverse of `to_dict`."""
        return cls(
            {str(k): str(v) for k, v in dict(d.get("args", {})).items()},
            tuple(map(str, d.get("given", ()))),
            tuple(map(str, d.get("unused", ()))),
            tuple(map(str, d.get("optenv_defaults", ()))),
            tuple(map(str, d.get("warnings", ()))),
            str(d.get("source_map", "")),
        )


def _listed(items: Iterable[str]) -> str:
    names = list(items)
    shown = ", ".join(names[:MAX_LISTED])
    return shown + (f" and {len(names) - MAX_LISTED} more" if len(names) > MAX_LISTED else "")
