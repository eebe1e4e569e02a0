"""Benchmark: the everyday commands a newcomer runs, whole process, as ratios (issues 31, 40).

1. `armcli check` of the course spec next to `urdf_validate` (pip urdf-validator, a
   peer that validates URDFs with physics) on the URDF that spec builds (urdf/my_robot.urdf).
2. Issue 40's everyday commands on the course robot, each beside its old figure (CPU
   seconds measured on a fresh machine when the issue was filed, OLD) and beside a peer
   where one exists: `simulate` along pick.yaml next to a bare MuJoCo script stepping the
   exported arm as long (BARE); `simulate --plot` next to `simulate` (what the plot costs);
   `render`; `plan` from home to reach (its planning takes milliseconds: the rest is
   start-up); a 5 s drive with `--plot` next to the bare script stepping the exported
   whole robot as long; `view` until it prints its address (its start-up).
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
import signal
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
# [CPU s] issue 40's figures, measured on a fresh machine (wall ~ CPU there)
OLD = {"simulate": 2.0, "simulate --plot": 4.0, "render": 3.4, "drive --plot": 2.8, "view": 3.1,
       "plan": 2.0}  # fmt: skip
BARE = """
import sys
import mujoco
m = mujoco.MjModel.from_xml_path(sys.argv[1])
m.opt.timestep = float(sys.argv[3])
d = mujoco.MjData(m)
for _ in range(round(float(sys.argv[2]) / m.opt.timestep)):
    mujoco.mj_step(m, d)
"""
DRIVE = "commands:\n  - {linear: {x: 0.3}, time_from_start: 0.5}\n  - {time_from_start: 3.5}\n"


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


def view_startup(cmd: list[str]) -> float:
    """CPU seconds of `armcli view` from its start until it prints its address, then Ctrl-C."""
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=ENV,
                            text=True)  # fmt: skip
    assert proc.stdout is not None
    proc.stdout.readline()  # `armcli view: NAME at http://...`
    proc.send_signal(signal.SIGINT)
    _, _, usage = os.wait4(proc.pid, 0)
    return float(usage.ru_utime + usage.ru_stime)


def everyday(armcli: str, tmp: Path, reps: int) -> None:
    """Issue 40's commands beside their OLD figures and their peers (module docstring)."""
    spec, pick = ROOT / "specs" / "my_robot.yaml", ROOT / "specs" / "trajectories" / "pick.yaml"
    arm, whole = tmp / "arm" / "arm.xml", tmp / "whole" / "robot.xml"
    cpu([armcli, "export", "mjcf", str(spec), "-o", str(arm)])
    cpu([armcli, "export", "mjcf", str(spec), "--whole-robot", "--base", "free", "-o", str(whole)])
    drive = tmp / "drive.yaml"
    drive.write_text(DRIVE)
    sim = [armcli, "simulate", str(spec), "--trajectory", str(pick)]
    bare = [sys.executable, "-c", BARE]
    rows = [
        ("simulate", sim, [*bare, str(arm.parent / "scene.xml"), "7.0", "0.001"], "MuJoCo"),
        ("simulate --plot", [*sim, "--plot", str(tmp / "t.png")], sim, "simulate"),
        ("render", [armcli, "render", str(spec), "-o", str(tmp / "r.png")], None, ""),
        ("plan", [armcli, "plan", str(spec), "--to", "reach", "-o", str(tmp / "p.yaml")], None, ""),
        ("drive --plot", [armcli, "simulate", str(spec), "--cmd-vel", str(drive), "--plot",
                          str(tmp / "d.png")],
         [*bare, str(whole.parent / "scene.xml"), "5.5", "0.001"], "MuJoCo"),
    ]  # fmt: skip
    for name, ours, peer, label in rows:
        cpu(ours)  # untimed: warm the caches
        if peer is None:
            a = statistics.median(cpu(ours) for _ in range(reps))
            print(f"{name}: {a:.2f} CPU s (was {OLD[name]:.1f}, x{a / OLD[name]:.2f})")
            continue
        a, b, r = paired(ours, peer, reps)
        print(f"{name}: {a:.2f} CPU s (was {OLD[name]:.1f}, x{a / OLD[name]:.2f}); {label} "
              f"{b:.2f} CPU s; ratio {r:.2f}")  # fmt: skip
    view = [armcli, "view", str(spec), "--port", "0", "--save-dir", str(tmp)]
    view_startup(view)
    a = statistics.median(view_startup(view) for _ in range(reps))
    print(f"view start-up: {a:.2f} CPU s (was {OLD['view']:.1f}, x{a / OLD['view']:.2f})")


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
    spec = ROOT / "specs" / "my_robot.yaml"
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
        everyday(armcli, Path(tmp), reps)
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
