"""The CLI's flags for the library's names, in the errors the library raises.

Library code names what a Python caller passed (`SimOptions.dt`, `jobs`), never a
flag; each command lists once which flag sets which name and runs its library calls
inside `flag_errors(...)`, so its messages say `--dt` as before.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from armcli.errors import InputError


def option_flags(cls: Any, **flags: str) -> dict[str, str]:
    """`Cls.field` -> `--field` (underscores as dashes) for each field of a dataclass.

    `flags` overrides the flag of a field whose option is spelled otherwise.
    """
    fields = [f.name for f in dataclasses.fields(cls)]
    unknown = set(flags) - set(fields)
    if unknown:  # a renamed field would silently lose its flag
        raise ValueError(f"{cls.__name__} has no field {', '.join(sorted(unknown))}")
    return {
        f"{cls.__name__}.{name}": flags.get(name, "--" + name.replace("_", "-")) for name in fields
    }


@contextmanager
def flag_errors(*names: Mapping[str, str]) -> Iterator[None]:
    """Re-raise an InputError from the block with the library's names as the CLI's flags."""
    table = {k: v for mapping in names for k, v in mapping.items()}
    try:
        yield
    except InputError as exc:
        renamed = exc.renamed(table)
        if renamed is exc:
            raise
        raise renamed from None
