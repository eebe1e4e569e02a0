"""Helpers for the package-rule tests: generated packages, edits, findings."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

from armcli.check.findings import Finding
from armcli.check.options import CheckOptions
from armcli.check.ros_packages.run import check_packages
from armcli.ros.packages import ros_packages
from armcli.spec.load import load_spec
from tests.helpers import DEFAULT_SPEC

SAMPLES = 200  # collision-matrix samples: the matrix does not matter to these rules


def generate(out: Path, target: str, spec: Path = DEFAULT_SPEC) -> Path:
    """ros-package's three packages for `spec` written under `out`."""
    pkgs = ros_packages(load_spec(spec), label=spec.name, samples=SAMPLES, target=target)
    for rel, data in pkgs.files.items():
        path = out / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    return out


def copy(src: Path, dst: Path) -> Path:
    """A private copy of generated packages to edit."""
    shutil.copytree(src, dst)
    return dst


def edit(path: Path, old: str, new: str, count: int = 1) -> None:
    """Replace `old` (which must be there) by `new` in a text file."""
    text = path.read_text()
    assert old in text, f"{old!r} not in {path}"
    path.write_text(text.replace(old, new, count))


def findings(root: Path, **kw: object) -> list[Finding]:
    """Every finding of `check DIR` on `root` (descriptions and package rules)."""
    result = check_packages(root, CheckOptions(), **kw)  # type: ignore[arg-type]
    return [f for r in result.results for f in r.findings]


def package_rules(found: list[Finding]) -> set[str]:
    """The ros-* and input-unusable rules among findings."""
    return {f.rule for f in found if f.rule.startswith("ros-") or f.rule == "input-unusable"}


Edit = Callable[[Path], None]
