"""compiled.Extension: one rule for the four extensions (stale, missing, switched off)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from armcli.compiled import Extension
from armcli.plan import native as plan_native
from armcli.sim import native as sim_native


def test_a_missing_module_says_it_is_not_installed() -> None:
    ext = Extension("armcli.sim._no_such_extension", (Path(__file__),))
    assert ext.load() is None
    assert ext.why_missing().startswith("the armcli.sim._no_such_extension extension is not")


def test_the_switch_turns_every_extension_off(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ARMCLI_NO_NATIVE", "1")
    ext = Extension("armcli.sim._rollout", sim_native.ROLLOUT.sources)
    assert ext.load() is None and ext.why_missing() == "ARMCLI_NO_NATIVE is set"


def test_an_edited_source_is_refused_and_use_overrides(tmp_path: Path) -> None:
    if sim_native.load() is None:
        pytest.skip(f"the simulator is not built: {sim_native.why_missing()}")
    edited = tmp_path / "rollout.cpp"
    edited.write_bytes(sim_native.SOURCE.read_bytes() + b"// edited\n")
    ext = Extension("armcli.sim._rollout", (edited,))
    assert ext.load() is None
    assert (
        ext.why_missing()
        == "armcli.sim._rollout was built from another rollout.cpp (run make native)"
    )
    ext.use(sim_native.load())
    assert ext.load() is sim_native.load() and ext.why_missing() == ""
    ext.forget()
    assert ext.load() is None


def test_the_hashes_are_cmakes() -> None:
    # CMakeLists.txt: one source -> its file's SHA-256; several -> SHA-256 of their hex lines
    one = sim_native.ROLLOUT
    assert one.source_hash() == hashlib.sha256(one.sources[0].read_bytes()).hexdigest()
    lines = "".join(
        hashlib.sha256(p.read_bytes()).hexdigest() + "\n" for p in plan_native.PLANNER.sources
    )
    assert plan_native.source_hash() == hashlib.sha256(lines.encode()).hexdigest()
    for mod, ext in ((sim_native.load(), one), (plan_native.load(), plan_native.PLANNER)):
        if mod is not None:  # a loaded extension was built from exactly these sources
            assert ext.source_hash() == mod.SOURCE_SHA256
