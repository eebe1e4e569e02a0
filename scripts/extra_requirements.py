"""Print the requirements of one optional-dependency extra of pyproject.toml, one per line.

`pip install -e '.[dev]'` would rebuild armcli (and recompile its engine) only to add tools;
`make test` installs the extra's requirements alone, expanding `armcli[other]` references,
so pyproject.toml stays the one list.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

from packaging.requirements import Requirement


def requirements(extra: str, extras: dict[str, list[str]], seen: set[str]) -> list[str]:
    out: list[str] = []
    if extra in seen:
        return out
    seen.add(extra)
    for text in extras[extra]:
        req = Requirement(text)
        if req.name == "armcli":
            for inner in sorted(req.extras):
                out += requirements(inner, extras, seen)
        else:
            out.append(text)
    return out


def main() -> None:
    project = tomllib.loads(Path("pyproject.toml").read_text())["project"]
    print("\n".join(requirements(sys.argv[1], project["optional-dependencies"], set())))


if __name__ == "__main__":
    main()
