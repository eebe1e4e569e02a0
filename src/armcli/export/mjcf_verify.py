"""MuJoCo compiles the exported files before they are written, where it is installed.

The export's own rules (mjcf_mass, mjcf_meshes) follow MuJoCo's compiler, but only
MuJoCo knows every rule of the version the user runs, so the finished files are
compiled from memory (the scene, which includes the model, and the meshes as assets):
a model MuJoCo refuses is never written and the command exits 1 with MuJoCo's reason.
MuJoCo is a dependency of armcli (`simulate --cmd-vel` runs on it), imported here only
when an export runs; an environment without it gets a report saying the model was not
compiled.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass

from armcli.errors import ExportRefusedError

_ELEMENT = re.compile(r"Element name '([^']*)'")
_PREFIX = re.compile(r"^(?:XML )?Error:\s*")


@dataclass(frozen=True)
class Verdict:
    """Whether MuJoCo compiled the files, and one line saying what it found."""

    compiled: bool
    text: str


def compile_check(files: Mapping[str, bytes], scene: str, source: str) -> Verdict:
    """Compile `scene` with the other files as its assets; ExportRefusedError if refused."""
    try:
        import mujoco
    except ImportError:
        return Verdict(False, "not compiled: MuJoCo is not installed (pip install mujoco)")
    assets = {name: data for name, data in files.items() if name != scene}
    try:
        m = mujoco.MjModel.from_xml_string(files[scene].decode("utf-8"), assets)
    except ValueError as exc:
        raise ExportRefusedError(
            source, f"MuJoCo {mujoco.__version__} refuses the exported model: {_reason(exc)}"
        ) from None
    mass = float(sum(m.body_mass))
    return Verdict(
        True,
        f"MuJoCo {mujoco.__version__} compiles it: {m.nbody - 1} bodies, {m.nv} degrees of "
        f"freedom, {m.nu} actuators, {mass:.4g} kg",
    )


def _reason(exc: ValueError) -> str:
    """MuJoCo's message on one line, naming the element it blames."""
    lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
    first = lines[0] if lines else "unknown error"
    while _PREFIX.match(first):
        first = _PREFIX.sub("", first, count=1)
    named = _ELEMENT.search(str(exc))
    return f"{first} (element {named.group(1)!r})" if named and named.group(1) else first
