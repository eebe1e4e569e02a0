"""One safe expansion's state: its allowed roots, inputs, files read and findings.

`ExpansionState.read` is the only way the safe expander (xacro.safe) reads a file: confined
to the allowed roots, size-capped, UTF-8 only, no DOCTYPE or entity declarations.
`ProblemError` carries a refusal or failure out through xacro's own exception wrapping.
"""

from __future__ import annotations

import glob
import os
import time
from collections.abc import Sequence
from pathlib import Path

from armcli.io.doctype import declares_doctype
from armcli.io.packages import real_roots
from armcli.io.userfile import read_regular
from armcli.xacro.args import Expansion, XacroInputs

MAX_XACRO_FILE_BYTES = 2_000_000  # one xacro or YAML file read during expansion


class ProblemError(Exception):
    """Raised inside xacro; carries a refusal or failure out through xacro's wrapping."""

    def __init__(
        self,
        message: str,
        needle: str | None = None,
        *,
        refused: bool = True,
        file: str | None = None,
        line: int | None = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.needle = needle  # text to find in the files read, for the line
        self.refused = refused
        self.file = file  # known exactly (a YAML mark), else found from needle
        self.line = line


class Recorded(dict[str, str]):
    """xacro's argument mapping, remembering which names the file declared or read."""

    def __init__(self, given: dict[str, str]) -> None:
        super().__init__(given)
        self.seen: set[str] = set()

    def __contains__(self, key: object) -> bool:
        self.seen.add(str(key))
        return super().__contains__(key)

    def __getitem__(self, key: str) -> str:
        self.seen.add(key)
        return super().__getitem__(key)


class ExpansionState:
    """Roots, inputs, files read, counters and findings of one expansion."""

    def __init__(self, top: Path, roots: Sequence[Path], inputs: XacroInputs) -> None:
        self.top = top
        self.roots = [Path(os.path.realpath(r)) for r in roots]
        self.inputs = inputs
        self.args = Recorded(dict(inputs.args))
        self.files: dict[str, str] = {}
        self.calls = 0
        self.start = time.monotonic()
        self.warnings: list[str] = []
        self.optenv_defaults: list[str] = []
        self.sources: list[str] = []  # files parsed, in order: xacro.lines' file indices

    def add_package(self, root: Path) -> None:
        """Allow reads inside a package `$(find)` resolved (and its real directories)."""
        for r in real_roots(root):
            if r not in self.roots:
                self.roots.append(r)

    def confine(self, path: str, what: str) -> Path:
        """`path` with symlinks resolved; ProblemError when it leaves the allowed roots."""
        real = Path(os.path.realpath(path))
        if not any(real.is_relative_to(r) for r in self.roots):
            raise ProblemError(
                f"{what} {path!r} is outside the allowed directories", os.path.basename(path)
            )
        return real

    def read(self, path: str, what: str) -> str:
        """The text of a confined file: UTF-8 only, no DOCTYPE or entity declarations.

        In UTF-16 a DOCTYPE hides from a byte search and the XML parser follows the file's
        own encoding, so the text is decoded strictly and handed on as str (issue 20).
        """
        real = self.confine(path, what)
        data = read_regular(real, max_bytes=MAX_XACRO_FILE_BYTES, what=what)
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise ProblemError(f"{what} {path!r} is not UTF-8 text", path) from None
        if "\x00" in text:  # UTF-16 without a byte-order mark is valid UTF-8 full of NULs
            raise ProblemError(f"{what} {path!r} holds NUL characters", path)
        if declares_doctype(text):  # its prolog's: a comment naming one declares nothing
            raise ProblemError(f"{what} {path!r} declares a DOCTYPE/entities", path)
        self.files[str(real)] = text
        return text

    def include_files(self, spec: str) -> list[str]:
        """The files an include names, a glob matched only inside the allowed roots.

        The pattern's literal directory must be inside a root, and matches outside the
        roots (through symlinks) are dropped without a word: an error naming them told
        the file's author which files exist elsewhere (`/root/.*rc` -> `/root/.bashrc`).
        """
        if not glob.has_magic(spec):
            return [spec]
        literal = spec[: min(spec.find(c) for c in "*?[" if c in spec)]
        self.confine(os.path.dirname(literal) or ".", "include pattern")
        inside = [f for f in sorted(glob.glob(spec)) if self.inside(f)]
        if not inside:
            self.warnings.append(f"include pattern {spec!r} matches no file")
        return inside

    def inside(self, path: str) -> bool:
        """Whether `path` (symlinks resolved) lies in one of the allowed roots."""
        real = Path(os.path.realpath(path))
        return any(real.is_relative_to(r) for r in self.roots)

    def expansion(self) -> Expansion:
        """What the expansion used: arguments given, read and unused; optenv defaults."""
        given = tuple(self.inputs.args)
        return Expansion(
            args=dict(self.args),
            given=given,
            unused=tuple(n for n in given if n not in self.args.seen),
            optenv_defaults=tuple(dict.fromkeys(self.optenv_defaults)),
            warnings=tuple(dict.fromkeys(self.warnings)),
        )
