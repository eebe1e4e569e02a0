"""Reading a package's files as data: confined to DIR, bounded, one `Problem` per bad file.

Why a module of its own: every reader of the package checker (package.xml, launch files,
parameter YAML, SRDF) takes files a stranger wrote, so they all go through here: the real
path (symlinks followed) must lie inside DIR, the file must be a regular file under a size
cap, XML is parsed without DTDs, entities or network, and YAML by armcli's safe reader.
A file that fails becomes a `Problem` (file, line, message): one `input-unusable` finding.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from armcli.errors import InputError
from armcli.io.packages import inside
from armcli.io.userfile import read_regular
from armcli.io.xml import line_of, parse_xml
from armcli.io.yaml import YamlDoc, loads_yaml

__all__ = ["Jail", "Problem", "line_of"]

if TYPE_CHECKING:
    from lxml import etree

MAX_TEXT_BYTES = 1_000_000  # a launch file, parameter YAML, package.xml or SRDF
MAX_XML_DEPTH = 64


@dataclass(frozen=True)
class Problem:
    """A file of the packages that could not be read: where and why."""

    file: str
    line: int | None
    message: str

    @staticmethod
    def of(exc: InputError, file: Path | str) -> Problem:
        """The problem an InputError from a reader describes."""
        return Problem(exc.file or str(file), exc.line, exc.message)


@dataclass(frozen=True)
class Jail:
    """The directory the checker may read: DIR, by its real path."""

    root: Path  # as the user named it

    @property
    def real(self) -> Path:
        """DIR with symlinks resolved."""
        return Path(os.path.realpath(self.root))

    def allows(self, path: Path) -> bool:
        """Whether `path` (symlinks followed) lies inside DIR."""
        return inside(path, (self.real,))

    def read(self, path: Path, what: str = "file") -> bytes:
        """The bytes of a regular file inside DIR of at most MAX_TEXT_BYTES; InputError else."""
        if not self.allows(path):
            raise InputError(f"{what} resolves outside {self.root}; not read", file=path)
        return read_regular(path, max_bytes=MAX_TEXT_BYTES, what=what)

    def text(self, path: Path, what: str = "file") -> str:
        """A UTF-8 text file inside DIR."""
        raw = self.read(path, what)
        try:
            return raw.decode("utf-8")
        except UnicodeDecodeError as exc:
            line = raw[: exc.start].count(b"\n") + 1
            raise InputError(f"{what} is not UTF-8 text", file=path, line=line) from None

    def yaml(self, path: Path, what: str = "YAML file") -> YamlDoc:
        """A YAML file inside DIR, by armcli's safe reader (line numbers kept).

        A repeated key is merged as ROS reads it (rcl's parameter parser, yaml-cpp for
        MoveIt's files: the Setup Assistant itself writes `control_xacro:` twice).
        """
        return loads_yaml(self.text(path, what), str(path), merge_duplicates=True)

    def xml(self, path: Path, what: str = "XML file") -> etree._Element:
        """An XML file inside DIR, parsed without DTDs, entities or network."""
        return parse_xml(self.read(path, what), str(path), max_depth=MAX_XML_DEPTH)
