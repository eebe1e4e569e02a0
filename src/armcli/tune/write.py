"""`--write`: put the tuned gains into the spec's `control.gains`, in place.

A targeted text edit, not a re-dump: ruamel.yaml's round-trip parser gives the line and
column of every existing `kp`/`kd` value, and only those characters change, so comments,
alignment and every other byte of the spec stay as they were. A joint without an entry
gets one line appended to the `control.gains` block (in the block's own indentation).
The new text must parse as a valid spec with exactly the new gains before it replaces
the file atomically; a file that is not writable is refused before anything is written.
"""

from __future__ import annotations

import io
import os
import re
import stat
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from armcli.errors import InputError
from armcli.io.files import write_file_atomic
from armcli.io.yaml import read_text
from armcli.spec.load import loads_spec

_SCALAR = re.compile(r"[^\s,}\]#]+")


def check_writable(path: Path) -> None:
    """Raise InputError unless `path` is an existing file we may overwrite.

    A file without any write permission bit counts as read-only even for root, who could
    write it anyway: `chmod a-w` says the user does not want it changed.
    """
    if not path.is_file():
        raise InputError("spec file not found", file=path, field="control.gains")
    no_write_bit = not path.stat().st_mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH)
    if no_write_bit or not os.access(path, os.W_OK) or not os.access(path.parent, os.W_OK):
        raise InputError(
            "spec file is read-only; nothing written", file=path, field="control.gains"
        )


def fmt_gain(x: float) -> str:
    """The text a gain is written as: 4 significant digits, as reported.

    Never in exponent form: PyYAML reads `1e+04` as a string.
    """
    import numpy as np

    return str(np.format_float_positional(float(f"{x:.4g}"), trim="-"))


def _load_rt(text: str, path: Path) -> Any:
    from ruamel.yaml import YAML
    from ruamel.yaml.error import YAMLError

    try:
        return YAML(typ="rt").load(io.StringIO(text))
    except YAMLError as exc:
        raise InputError(f"cannot parse for --write: {exc}", file=path) from None


def _gains_block(root: Any, path: Path) -> Any:
    from ruamel.yaml.comments import CommentedMap

    control = root.get("control") if isinstance(root, CommentedMap) else None
    gains = control.get("gains") if isinstance(control, CommentedMap) else None
    if not isinstance(gains, CommentedMap) or gains.fa.flow_style() or not gains:
        raise InputError(
            "no block mapping `control.gains` to update; add one entry such as "
            "`control: {gains: {JOINT: {kp: 1, kd: 1}}}` by hand, then rerun",
            file=path,
            field="control.gains",
        )
    return gains


def updated_text(text: str, path: Path, gains: Mapping[str, tuple[float, float]]) -> str:
    """`text` with kp, kd of each joint in `gains` replaced or added (see module doc)."""
    block = _gains_block(_load_rt(text, path), path)
    lines = text.splitlines(keepends=True)
    edits: list[tuple[int, int, str]] = []  # (line, col, new) for existing values
    missing = []
    for joint, (kp, kd) in gains.items():
        entry = block.get(joint)
        if entry is None:
            missing.append(joint)
            continue
        for key, val in (("kp", kp), ("kd", kd)):
            line, col = entry.lc.value(key)
            edits.append((line, col, fmt_gain(val)))
    for line, col, new in sorted(edits, reverse=True):
        m = _SCALAR.match(lines[line], col)
        if m is None:  # pragma: no cover - ruamel points at a scalar
            raise InputError("unexpected layout in control.gains", file=path, line=line + 1)
        lines[line] = lines[line][: m.start()] + new + lines[line][m.end() :]
    if missing:
        last = list(block.keys())[-1]
        last_line = _last_line(block, last, lines)
        indent = " " * block.lc.key(last)[1]
        add = [
            f"{indent}{j}: {{kp: {fmt_gain(gains[j][0])}, kd: {fmt_gain(gains[j][1])}}}\n"
            for j in missing
        ]
        if not lines[last_line].endswith("\n"):
            lines[last_line] += "\n"
        lines[last_line + 1 : last_line + 1] = add
    return "".join(lines)


def _last_line(block: Any, key: str, lines: list[str]) -> int:
    """Index of the last text line of `block[key]`'s entry."""
    line = int(block.lc.key(key)[0])
    value = block[key]
    if hasattr(value, "lc") and not value.fa.flow_style():
        for k in value:
            line = max(line, int(value.lc.value(k)[0]))
    return line


def write_gains(path: Path, gains: Mapping[str, tuple[float, float]]) -> None:
    """Update `control.gains` in the spec at `path` atomically (see the module docstring)."""
    write_file_atomic(path, edited_spec(path, gains))


def edited_spec(path: Path, gains: Mapping[str, tuple[float, float]]) -> bytes:
    """The spec at `path` with `control.gains` updated, checked to read back; not written."""
    check_writable(path)
    text = read_text(path, what="spec")
    new = updated_text(text, path, gains)
    spec = loads_spec(new, str(path))
    for joint, (kp, kd) in gains.items():
        got = spec.control.gains.get(joint)
        if got is None or (fmt_gain(got.kp), fmt_gain(got.kd)) != (fmt_gain(kp), fmt_gain(kd)):
            raise InputError(
                f"the edited spec does not read back {joint}'s gains; nothing written",
                file=path,
                field="control.gains",
            )
    return new.encode("utf-8")
