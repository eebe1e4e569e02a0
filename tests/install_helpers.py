"""Install armcli the way a user does: a wheel in a fresh venv, from a local wheelhouse.

The fresh venv must not see the development venv (so a dependency missing from
pyproject.toml fails the test), yet the test should not download the world each run.
The wheelhouse therefore holds exactly the distributions installed here that armcli needs
at run time (the closure of its `Requires-Dist`, at the installed versions) plus the
`[build-system] requires`; it is fetched once with `pip wheel` and cached under
~/.cache/armcli/wheelhouse, keyed by that list. The install itself is `--no-index`.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib
import venv
from importlib import metadata
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
# Not part of a source distribution: local state, caches and outputs of the checkout.
TOP_LEVEL_LOCAL = {".git", ".venv", "build", "dist", "out", "ros", ".hypothesis", "MUJOCO_LOG.TXT"}
ANYWHERE_LOCAL = shutil.ignore_patterns("__pycache__", "*.egg-info", ".*_cache")
# Timeouts sized to what was measured on the project's 2-core build machine under load 9-18
# (README, "Set up"): the wheel build, i.e. the build requirements' install plus the C++
# compile, took 13.7 min; it gets three times that. Fetching the wheelhouse and installing
# into a fresh venv took under 5 min; they get 20.
PIP_TIMEOUT_S = 1200
WHEEL_BUILD_TIMEOUT_S = 3 * 14 * 60


def _pip(*args: str | Path, timeout: float = PIP_TIMEOUT_S) -> None:
    cmd = [sys.executable, "-m", "pip", "--disable-pip-version-check", *map(str, args)]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
    if proc.returncode != 0:
        tail = "\n".join(proc.stderr.strip().splitlines()[-20:])
        raise RuntimeError(f"{' '.join(cmd[3:6])} ... failed ({proc.returncode}):\n{tail}")


def runtime_pins(name: str = "armcli") -> list[str]:
    """`dist==version` for every installed distribution `name` needs at run time."""
    pins: dict[str, str] = {}
    todo: list[tuple[str, frozenset[str]]] = [(name, frozenset())]
    seen: set[tuple[str, frozenset[str]]] = set()
    while todo:
        item = todo.pop()
        if item in seen:
            continue
        seen.add(item)
        dist = metadata.distribution(item[0])
        pins[canonicalize_name(dist.metadata["Name"])] = dist.version
        for text in dist.requires or []:
            req = Requirement(text)
            extras = item[1] or {""}
            if req.marker is None or any(req.marker.evaluate({"extra": e}) for e in extras):
                todo.append((req.name, frozenset(req.extras)))
    pins.pop(canonicalize_name(name))
    return sorted(f"{n}=={v}" for n, v in pins.items())


def build_requires() -> list[str]:
    return list(tomllib.loads((ROOT / "pyproject.toml").read_text())["build-system"]["requires"])


def _cache_root() -> Path:
    base = os.environ.get("ARMCLI_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "armcli"
    )
    return Path(base) / "wheelhouse"


def wheelhouse() -> Path:
    """A directory of wheels for the runtime closure and the build requirements (cached)."""
    pins, build = runtime_pins(), build_requires()
    key = hashlib.sha256("\n".join([*pins, "--", *build, sys.version]).encode()).hexdigest()
    path = _cache_root() / key[:16]
    if path.is_dir():
        return path
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=path.parent) as tmp:
        _pip("wheel", "-q", "--no-deps", "-w", tmp, *pins)  # a wheel as-is, an sdist built
        _pip("wheel", "-q", "-w", tmp, *build)
        os.rename(tmp, path)  # complete or absent: a killed run never leaves half a wheelhouse
        os.mkdir(tmp)  # for TemporaryDirectory's cleanup
    return path


def _not_source(directory: str, names: list[str]) -> set[str]:
    """Names copytree skips: checkout-local state at the top, caches anywhere.

    Only at the top: the checkout's own build/ is local state.
    """
    skip = set(ANYWHERE_LOCAL(directory, names))
    if Path(directory) == ROOT:
        skip |= TOP_LEVEL_LOCAL & set(names)
    return skip


def build_wheel(out: Path, house: Path) -> Path:
    """`pip wheel --no-deps` of a clean copy of the checkout (no stale build/ reused)."""
    src = out / "src-copy"
    shutil.copytree(ROOT, src, symlinks=True, ignore=_not_source)
    dist = out / "dist"
    _pip(
        "wheel", "-q", "--no-deps", "--no-index", "--find-links", house, "-w", dist, src,
        timeout=WHEEL_BUILD_TIMEOUT_S,
    )  # fmt: skip
    (wheel,) = dist.glob("armcli-*.whl")
    return wheel


def fresh_venv(where: Path, wheel: Path, house: Path) -> Path:
    """A new venv (no system site-packages, no pip) with the wheel installed; its bin/."""
    venv.EnvBuilder(with_pip=False, system_site_packages=False).create(where)
    python = where / "bin" / "python"
    _pip("--python", python, "install", "-q", "--no-index", "--find-links", house, wheel)
    return where / "bin"
