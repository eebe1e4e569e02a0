"""Which spec a command uses when none is given on the command line.

A new user runs `armcli init`, then `armcli build` with no argument; a checkout of this
repository keeps its specs under `specs/`. The search order is therefore: the argument,
`./armcli.yaml` (what `armcli init` writes), then `specs/*.yaml` (the only one, or
`specs/my_robot.yaml` among several). Paths stay relative to the current directory so
generated files name their spec the way the user would.
"""

from __future__ import annotations

from pathlib import Path

from armcli.defaults import DEFAULT_SPEC, SPEC_FILE, SPECS_DIR
from armcli.errors import NoSpecError

INIT_HINT = "run `armcli init` to write an example spec here, or pass a spec file"


def find_spec(given: Path | None) -> Path:
    """The spec to use: `given` if set, else the one found in the current directory.

    Raises:
        NoSpecError: nothing given and no `./armcli.yaml` or unambiguous `specs/*.yaml`;
            the message names the command to run.
    """
    if given is not None:
        return given
    if SPEC_FILE.is_file():
        return SPEC_FILE
    found = sorted(p for p in SPECS_DIR.glob("*.yaml") if p.is_file())
    if len(found) == 1:
        return found[0]
    if DEFAULT_SPEC in found:
        return DEFAULT_SPEC
    if found:
        names = ", ".join(p.as_posix() for p in found)
        raise NoSpecError(f"no spec given and several in {SPECS_DIR}/ ({names}); pass one")
    raise NoSpecError(f"no spec given and no ./{SPEC_FILE} or {SPECS_DIR}/*.yaml here; {INIT_HINT}")
