"""Optional compiled rollout (`_native/rollout.cpp`) built against the `pin` wheel's headers.

`make native` compiles it once (about two minutes: Pinocchio is header-only templates)
into a cache directory keyed by a hash of the source, the compile command and the `pin`
version, so a changed source or upgraded Pinocchio never loads a stale library. At run
time `load()` only looks the library up; it never compiles, and callers fall back to the
identical Python loop in `rollout.py` when it is missing.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from armcli.errors import BuildError
from armcli.io.files import write_file_atomic
from armcli.sim import rollout as ro

SOURCE = Path(__file__).parent / "_native" / "rollout.cpp"
ABI_VERSION = 1
DEFINES = [
    "BOOST_MPL_LIMIT_LIST_SIZE=30",
    "BOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "BOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "BOOST_FUSION_INVOKE_MAX_ARITY=12",
]  # from pinocchio::pinocchio_headers INTERFACE_COMPILE_DEFINITIONS
# No -march=native and no FMA contraction: results must match the Python loop to ~1e-12.
FLAGS = ["-std=c++17", "-O2", "-ffp-contract=off", "-fPIC", "-shared"]
_cache: dict[str, Any] = {}


def _prefix() -> Path:
    return Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"


def _command(out: Path) -> list[str]:
    inc = _prefix() / "include"
    cxx = os.environ.get("CXX", "g++")
    return [
        cxx,
        *FLAGS,
        *[f"-D{d}" for d in DEFINES],
        f"-I{inc}",
        f"-I{inc / 'eigen3'}",
        f"-I{inc / 'pinocchio' / 'deprecated'}",
        str(SOURCE),
        "-o",
        str(out),
    ]


def cache_dir() -> Path:
    """Where compiled libraries go: $ARMCLI_CACHE_DIR, else the XDG cache, plus `native`."""
    base = os.environ.get("ARMCLI_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "armcli"
    )
    return Path(base) / "native"


def library_path() -> Path:
    """Where the library for this source, compile command and pin version lives."""
    h = hashlib.sha256(SOURCE.read_bytes())
    h.update(" ".join(_command(Path("x"))).encode())
    h.update(metadata.version("pin").encode())
    h.update(sys.implementation.cache_tag.encode())
    return cache_dir() / f"rollout-{h.hexdigest()[:16]}.so"


def build(force: bool = False) -> Path:
    """Compile the rollout library if needed; returns its path. Raises BuildError."""
    if not SOURCE.is_file():
        raise BuildError(f"{SOURCE} is not installed; the Python simulator is used instead")
    path = library_path()
    if path.exists() and not force:
        return path
    if shutil.which(os.environ.get("CXX", "g++")) is None:
        raise BuildError("no C++ compiler (g++) found; the Python simulator is used instead")
    if not (_prefix() / "include" / "pinocchio").is_dir():
        raise BuildError(f"Pinocchio headers not found under {_prefix()}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
        out = Path(tmp) / "rollout.so"
        proc = subprocess.run(_command(out), capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            tail = "\n".join(proc.stderr.strip().splitlines()[-15:])
            raise BuildError(f"compiling {SOURCE.name} failed:\n{tail}")
        write_file_atomic(path, out.read_bytes())  # a concurrent loader never sees half a file
    _cache.clear()
    return path


def why_missing() -> str:
    """Why `load()` gave None, for the fallback message: not built, or failed to load."""
    if not SOURCE.is_file():  # a wheel install ships no C++ source
        return f"this installation has no {SOURCE.name}"
    path = library_path()
    return f"{path} does not exist" if not path.exists() else "it failed to load"


def load() -> Any | None:
    """The loaded library, or None when it has not been built (never compiles)."""
    if not SOURCE.is_file():  # a wheel install ships no C++ source: the Python loop runs
        return None
    path = library_path()
    key = str(path)
    if key in _cache:
        return _cache[key]
    lib = None
    if path.exists() and not os.environ.get("ARMCLI_NO_NATIVE"):
        try:
            lib = ctypes.CDLL(str(path))
            if lib.armcli_abi_version() != ABI_VERSION:
                lib = None
            else:
                lib.armcli_rollout.restype = ctypes.c_int
        except OSError:
            lib = None
    _cache[key] = lib
    return lib


def _ptr(a: np.ndarray, ctype: Any) -> Any:
    return a.ctypes.data_as(ctypes.POINTER(ctype))


def model_arrays(model: Any) -> dict[str, np.ndarray]:
    """The model as flat arrays the C++ side rebuilds it from (one-dof joints only)."""
    n = model.njoints - 1
    out = {
        "jtype": np.zeros(n, dtype=np.int32),
        "parent": np.zeros(n, dtype=np.int32),
        "placement": np.zeros((n, 12)),
        "axis": np.zeros((n, 3)),
        "inertia": np.zeros((n, 13)),
    }
    for i in range(n):
        jid = i + 1
        j = model.joints[jid]
        out["jtype"][i] = ro.JOINT_TYPES[j.shortname()]
        out["parent"][i] = model.parents[jid]
        M = model.jointPlacements[jid]
        out["placement"][i] = np.concatenate([M.rotation.reshape(-1), M.translation])
        ax = getattr(j, "axis", None)
        out["axis"][i] = ax if ax is not None else 0.0
        Y = model.inertias[jid]
        out["inertia"][i] = np.concatenate([[Y.mass], Y.lever, Y.inertia.reshape(-1)])
    return out


def rollout(
    lib: Any, plant: ro.Plant, q0: np.ndarray, v0: np.ndarray, ref: np.ndarray
) -> ro.Rollout:
    """One rollout through the library; same contract as `rollout.rollout_python`."""
    r = rollout_batch(lib, plant, q0[None, :], v0[None, :], ref)
    return r[0]


def rollout_batch(
    lib: Any, plant: ro.Plant, q0: np.ndarray, v0: np.ndarray, ref: np.ndarray
) -> list[ro.Rollout]:
    """Independent rollouts from each row of q0/v0 under the same reference."""
    m = model_arrays(plant.model)
    n = plant.model.nv
    batch = q0.shape[0]
    steps = (ref.shape[0] - 1) // (2 if plant.integrator == "rk4" else 1)
    Q = np.full((batch, steps + 1, n), np.nan)
    V = np.full((batch, steps + 1, n), np.nan)
    T = np.full((batch, steps, n), np.nan)
    F = np.zeros((batch, steps, n), dtype=np.uint8)
    fs = np.zeros(batch, dtype=np.int64)
    fj = np.zeros(batch, dtype=np.int32)
    fc = np.zeros(batch, dtype=np.int32)

    def c(a: Any) -> np.ndarray:
        return np.ascontiguousarray(a, dtype=float)

    grav = c(np.array(plant.model.gravity.linear))
    params, q0c, v0c, refc = c(plant.params), c(q0), c(v0), c(ref)
    dbl, i32 = ctypes.c_double, ctypes.c_int
    lib.armcli_rollout(
        i32(n), _ptr(m["jtype"], i32), _ptr(m["parent"], i32), _ptr(c(m["placement"]), dbl),
        _ptr(c(m["axis"]), dbl), _ptr(c(m["inertia"]), dbl), _ptr(grav, dbl), _ptr(params, dbl),
        i32(int(plant.gravity_comp)), dbl(plant.dt), i32(1 if plant.integrator == "rk4" else 0),
        ctypes.c_long(steps), i32(batch), dbl(plant.energy_max), _ptr(q0c, dbl), _ptr(v0c, dbl),
        _ptr(refc, dbl), _ptr(Q, dbl), _ptr(V, dbl), _ptr(T, dbl), _ptr(F, ctypes.c_ubyte),
        _ptr(fs, ctypes.c_long), _ptr(fj, i32), _ptr(fc, i32),
    )  # fmt: skip
    return [
        ro.Rollout(Q[b], V[b], T[b], F[b], int(fs[b]), int(fj[b]), int(fc[b])) for b in range(batch)
    ]


if __name__ == "__main__":  # `make native`
    try:
        print(build(force="--force" in sys.argv))
    except BuildError as exc:
        print(f"native: {exc}", file=sys.stderr)
        raise SystemExit(1) from None
