"""The compiled engine for tests: required wherever a C++ compiler exists.

A missing `armcli._rollout` extension on a machine that could have built it means the
build is broken; the tests say so instead of skipping (only a machine without a compiler
skips, with the reason).
"""

from __future__ import annotations

import shutil
from types import ModuleType

import pytest

from armcli.sim import native


def has_compiler() -> bool:
    return any(shutil.which(c) for c in ("c++", "g++", "clang++"))


def require_native() -> ModuleType:
    mod = native.load()
    if mod is not None:
        return mod
    if has_compiler():
        pytest.fail(
            f"compiled engine missing although a C++ compiler exists: {native.why_missing()}"
        )
    pytest.skip(f"no C++ compiler: {native.why_missing()}")


FAST = "native" if native.load() is not None or has_compiler() else "python"
