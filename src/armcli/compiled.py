"""armcli's compiled extensions, used only when built from the C++ sources beside them.

Why one module: the simulator, the planner, the camera's ray caster and the drive's steps
are four nanobind extensions built at install time (CMakeLists.txt), each carrying the
SHA-256 of the sources it was built from (`SOURCE_SHA256`). An editable install whose C++
changed without `make native` must not run stale code, ARMCLI_NO_NATIVE must switch every
one of them off, and `--version` must say why one is missing: one rule, written once.
"""

from __future__ import annotations

import hashlib
import importlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType


@dataclass
class Extension:
    """One compiled module: its import name and the sources its build hashes (CMake's order).

    One source is hashed as its file; several as the SHA-256 of their SHA-256 lines.
    """

    name: str  # e.g. "armcli.sim._rollout"
    sources: tuple[Path, ...]
    preload: str | None = "pinocchio"  # loads libpinocchio/libcoal the extension links to
    _loaded: tuple[ModuleType | None, str] | None = field(default=None, repr=False)

    def load(self) -> ModuleType | None:
        """The module, or None when it is missing, stale or ARMCLI_NO_NATIVE is set."""
        if self._loaded is None:
            self._loaded = self._import()
        return self._loaded[0]

    def why_missing(self) -> str:
        """Why `load()` returned None (empty when it did not), for a one-line message."""
        self.load()
        assert self._loaded is not None
        return self._loaded[1]

    def use(self, module: ModuleType | None, why: str = "switched off") -> None:
        """Answer `module` from now on (None: the Python path), as a benchmark compares them."""
        self._loaded = (module, "" if module is not None else why)

    def forget(self) -> None:
        """Ask again on the next `load()` (after the sources or the environment changed)."""
        self._loaded = None

    def source_hash(self) -> str:
        """The hash CMakeLists.txt computes over the sources."""
        if len(self.sources) == 1:
            return _sha256(self.sources[0].read_bytes())
        lines = "".join(_sha256(p.read_bytes()) + "\n" for p in self.sources)
        return _sha256(lines.encode())

    def _import(self) -> tuple[ModuleType | None, str]:
        if os.environ.get("ARMCLI_NO_NATIVE"):
            return None, "ARMCLI_NO_NATIVE is set"
        if self.preload is not None:
            importlib.import_module(self.preload)
        try:
            mod = importlib.import_module(self.name)
        except ImportError as exc:
            return None, f"the {self.name} extension is not installed ({exc})"
        if all(p.is_file() for p in self.sources) and self.source_hash() != getattr(
            mod, "SOURCE_SHA256", ""
        ):
            built = f"another {self.sources[0].name}" if len(self.sources) == 1 else "other sources"
            return None, f"{self.name} was built from {built} (run make native)"
        return mod, ""


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()
