"""Benchmark: the everyday commands a newcomer runs, whole process, as ratios (issue 31).

1. `armcli check` of the course spec next to `urdf_validate` (pip urdf-validator, a
   peer that validates URDFs with physics) on the URDF that spec builds (urdf/my_robot.urdf).
2. `armcli simulate --plot` of the course spec along pick.yaml next to the same run
   without a plot: what the plot costs.
3. `armcli check` of every example-robot-data URDF next to `urdf_validate` on the same
   file: the median of the per-file ratios, and the sums.

CPU seconds (user + system, the kernel's accounting of the finished process: what a
loaded machine disturbs least), each pair run in turn (A B A B ...) so a drift in the
machine's speed cancels in the ratio; the median is quoted. Any exit code counts (a check
with findings exits 1): the point is the time to the verdict. urdf_validate writes its
JSON report into a temporary directory, never beside the input.

Run with `make bench` (or `python bench/bench_first_hour.py [--quick]`: one repeat and
every fifth corpus file). Not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def cpu(cmd: list[str]) -> float:
    """CPU seconds (user + system) of one whole process, whatever its exit code."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=ENV)
    _, _, usage = os.wait4(proc.pid, 0)
    return float(usage.ru_utime + usage.ru_stime)


def paired(a: list[str], b: list[str], repeats: int) -> tuple[float, float, float]:
    """Median CPU seconds of A and of B, and the median of the pairwise ratios A / B."""
    ta, tb = [], []
    for _ in range(repeats):
        ta.append(cpu(a))
        tb.append(cpu(b))
    ratios = [x / y for x, y in zip(ta, tb, strict=True)]
    return statistics.median(ta), statistics.median(tb), statistics.median(ratios)


def corpus() -> list[Path]:
    """Every robots/**/*.urdf of the example-robot-data distribution."""
    dist = importlib.metadata.distribution("example-robot-data")
    files = [Path(str(dist.locate_file(f))) for f in dist.files or () if str(f).endswith(".urdf")]
    return sorted(p for p in files if "/robots/" in p.as_posix())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one repeat, every fifth corpus file")
    args = ap.parse_args()
    reps = 1 if args.quick else 3
    armcli, validate = str(BIN / "armcli"), str(BIN / "urdf_validate")
    spec, pick = ROOT / "specs" / "my_robot.yaml", ROOT / "specs" / "trajectories" / "pick.yaml"
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory() as tmp:
        ENV["PYTHONPYCACHEPREFIX"] = str(Path(tmp) / "pycache")
        reports = Path(tmp) / "reports"
        reports.mkdir()

        def peer(urdf: Path) -> list[str]:
            return [validate, str(urdf), "--output-dir", str(reports)]

        built = ROOT / "urdf" / "my_robot.urdf"
        cpu([armcli, "check", str(spec)]), cpu(peer(built))  # untimed: warm the caches
        a, b, r = paired([armcli, "check", str(spec)], peer(built), reps)
        print(f"check course spec: {a:.2f} CPU s; urdf_validate {b:.2f} CPU s; ratio {r:.2f}")
        sim = [armcli, "simulate", str(spec), "--trajectory", str(pick)]
        plot = [*sim, "--plot", str(Path(tmp) / "tracking.png")]
        a, b, r = paired(plot, sim, reps)
        print(f"simulate --plot: {a:.2f} CPU s; without a plot {b:.2f} CPU s; ratio {r:.2f}")
        files = corpus()[:: 5 if args.quick else 1]
        ratios, ours, theirs = [], 0.0, 0.0
        for urdf in files:
            a, b, r = paired([armcli, "check", str(urdf)], peer(urdf), 1)
            ratios.append(r)
            ours, theirs = ours + a, theirs + b
        print(
            f"check of {len(files)} example-robot-data URDFs: {ours:.1f} CPU s; urdf_validate "
            f"{theirs:.1f} CPU s; ratio of sums {ours / theirs:.2f}, median per file "
            f"{statistics.median(ratios):.2f} (min {min(ratios):.2f}, max {max(ratios):.2f})"
        )
    print(f"load average after: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
