"""The compiled simulator (`armcli.sim._rollout`): loading it and handing it a model.

The step is defined once, in `_native/rollout.cpp`, built at install time (`pip install .`,
`make install`; CMakeLists.txt) against the Pinocchio of the `pin` wheel; nothing compiles
at run time. An install without a C++ compiler has no simulator: `require()` says so and
how to get one. The extension carries the hash of the source it was built from, so an
editable install whose C++ changed without `make native` is refused instead of running
stale physics.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

from armcli.compiled import Extension
from armcli.errors import InputError

if TYPE_CHECKING:
    from armcli.sim import _rollout

SOURCE = Path(__file__).parent / "_native" / "rollout.cpp"
ROLLOUT = Extension("armcli.sim._rollout", (SOURCE,))
load = ROLLOUT.load  # the module, or None: not installed, stale, or ARMCLI_NO_NATIVE set
why_missing = ROLLOUT.why_missing


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
