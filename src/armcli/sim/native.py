"""The compiled simulator (`armcli.sim._rollout`): loading it and handing it a model.

The step is defined once, in `_native/rollout.cpp`, built at install time (`pip install .`,
`make install`; CMakeLists.txt) against the Pinocchio of the `pin` wheel; nothing compiles
at run time. An install without a C++ compiler has no simulator: `require()` says so and
how to get one. The extension carries the hash of the source it was built from, so an
editable install whose C++ changed without `make native` is refused instead of running
stale physics.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

from armcli.errors import InputError

if TYPE_CHECKING:
    from armcli.sim import _rollout

SOURCE = Path(__file__).parent / "_native" / "rollout.cpp"
_state: dict[str, Any] = {}


def load() -> ModuleType | None:
    """The extension module, or None when it is not installed (or ARMCLI_NO_NATIVE is set)."""
    if "module" not in _state:
        _state["module"], _state["why"] = _import()
    mod: ModuleType | None = _state["module"]
    return mod


def require() -> ModuleType:
    """The extension module.

    Raises:
        InputError: it is not installed, or stale; the message says how to build it.
    """
    mod = load()
    if mod is None:
        raise InputError(
            f"the simulator is unavailable: {why_missing()}; it is compiled when armcli is "
            "installed: install a C++ compiler (e.g. apt-get install g++) and reinstall armcli"
        )
    return mod


def _import() -> tuple[ModuleType | None, str]:
    if os.environ.get("ARMCLI_NO_NATIVE"):
        return None, "ARMCLI_NO_NATIVE is set"
    import pinocchio  # noqa: F401  (loads libpinocchio_default before the extension)

    try:
        from armcli.sim import _rollout
    except ImportError as exc:
        return None, f"the armcli.sim._rollout extension is not installed ({exc})"
    if SOURCE.is_file() and _sha256(SOURCE) != _rollout.SOURCE_SHA256:
        return None, f"armcli.sim._rollout was built from another {SOURCE.name} (run make native)"
    return _rollout, ""


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def why_missing() -> str:
    """Why `load()` returned None, for the one-line message."""
    load()
    why: str = _state["why"]
    return why


def compiled_model(mod: ModuleType, model: Any) -> _rollout.Model:
    """The extension's copy of a pinocchio.Model, exact: Pinocchio's own binary serialisation.

    Build once and reuse across rollouts of the same model.
    """
    import pinocchio as pin

    buf = pin.serialization.StreamBuffer()
    model.saveToBinary(buf)
    compiled: _rollout.Model = mod.load_model(buf.tobytes())
    return compiled


if __name__ == "__main__":  # `python -m armcli.sim.native`: is the simulator installed
    import sys

    if load() is None:
        print(f"armcli: compiled simulator unavailable: {why_missing()}", file=sys.stderr)
        raise SystemExit(1)
    print(f"armcli: compiled simulator {load()}")
