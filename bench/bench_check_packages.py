"""Benchmark: what the ROS package rules add to `armcli check` (issue 41: <= 2 s CPU).

A three-package workspace: ros-package's output for a spec (default specs/my_robot.yaml,
`--target jazzy`: description, bringup, MoveIt config; 9 launch files, 3 robot
descriptions). Side by side, in turn (A B A B ...), fresh processes through the real
command, output thrown away:

- A: `armcli check DIR`: packages found, launch files read, the descriptions expanded and
  checked, then the package rules;
- B: today's URDF check of the same descriptions: `armcli check D1 D2 D3 --package-dir ...`
  (the xacro files A found, in one process, their packages named).

CPU time is user + system of the process and everything it waited for (the safe xacro
evaluator runs in a child per expansion), from `getrusage(RUSAGE_CHILDREN)`; the median of
the pairwise differences A - B is what the package rules cost. Run
`python bench/bench_check_packages.py [-n 7] [--spec SPEC]`. Not a test: numbers depend on
the machine and its load (printed).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUDGET_S = 2.0  # [s] CPU the issue allows the package rules beyond the URDF check
EXPANDED = "#expanded"


def workspace(spec: Path, out: Path) -> Path:
    """ros-package's three packages for `spec` under `out` (jazzy target)."""
    from armcli.ros.packages import ros_packages
    from armcli.spec.load import load_spec

    pkgs = ros_packages(load_spec(spec), label=spec.name, samples=300, target="jazzy")
    for rel, data in pkgs.files.items():
        path = out / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    return out


def timed(args: list[str]) -> tuple[float, float, str]:
    """(wall, cpu, stdout) of `armcli ARGS` in a fresh process, children included."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    res = subprocess.run(
        [sys.executable, "-m", "armcli.cli", *args],
        capture_output=True, text=True, check=False, cwd=ROOT,
    )  # fmt: skip
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode not in (0, 1):
        raise SystemExit(f"armcli {' '.join(args)} failed: {res.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, res.stdout


def main() -> None:
    """Alternate A and B, print their medians and the median difference."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=7, help="pairs of runs (default 7)")
    ap.add_argument("--spec", type=Path, default=ROOT / "specs" / "my_robot.yaml")
    opts = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ws = workspace(opts.spec, Path(tmp))
        _, _, out = timed(["check", str(ws), "--format", "json"])
        files = [f["file"] for f in json.loads(out)["files"] if f["file"].endswith(EXPANDED)]
        found = [f.removesuffix(EXPANDED) for f in files]
        dirs = [f"--package-dir={p.name}={p}" for p in sorted(ws.iterdir()) if p.is_dir()]
        a_args = ["check", str(ws)]
        b_args = ["check", *found, *dirs]
        a, b = [], []
        for _ in range(opts.n):
            a.append(timed(a_args)[:2])
            b.append(timed(b_args)[:2])
    diff = statistics.median(x[1] - y[1] for x, y in zip(a, b, strict=True))
    load = os.getloadavg()
    print(f"workspace: 3 packages from {opts.spec.name} (jazzy), {len(found)} descriptions")
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; {opts.n} pairs")
    for name, runs in (("A check DIR", a), ("B check the descriptions", b)):
        wall = statistics.median(r[0] for r in runs)
        cpu = statistics.median(r[1] for r in runs)
        print(f"{name:28s} wall {wall:6.3f} s   CPU {cpu:6.3f} s")
    ratio = statistics.median(x[1] / y[1] for x, y in zip(a, b, strict=True))
    verdict = "within" if diff <= BUDGET_S else "OVER"
    print(f"package rules: +{diff:.3f} s CPU (median of pairs; ratio A/B {ratio:.2f}), "
          f"{verdict} the {BUDGET_S:g} s budget")  # fmt: skip


if __name__ == "__main__":
    main()
