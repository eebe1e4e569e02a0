"""Benchmark: what simulated sensors add to a drive, and the ray casting against its floor.

The rover (specs/rover.yaml: the course robot) drives its example drive among the boxes
of specs/rover/world.yaml for DURATION s at dt = 1 ms, arm holding still, three ways in
turn (A B C A B C ...): without sensors, with the 360-ray 2-D lidar at 10 Hz alone, with
the 160 x 120 depth camera at 10 Hz alone. CPU seconds (time.process_time) of the run
(`drive.job.run`: stepping, the sensors, their readings; the model is prepared once per
variant, untimed), the ratio to the bare drive taken round by round. Then the whole
command (`armcli simulate ... -o run.mcap`, a fresh process: CPU from wait4) the same way,
so the MCAP's sensor messages are counted too.

Beside it, one scan and one depth image in a fixed state: the samplers' casting against
the floor to beat, a plain Python loop of mj_ray calls, ray by ray (for the depth image
also mj_multiRay without the compiled pinhole caster).

Targets (issue 39): lidar <= 1.10x the bare drive's CPU, depth camera <= 1.50x. Run with
`make bench` or `python bench/bench_sensors.py [--quick]`. Not a test: numbers depend on
the machine and its load (printed).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from armcli.drive import job as drive  # noqa: E402
from armcli.sim.options import SimOptions  # noqa: E402
from armcli.sim.sensors import raycast, scanners  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402

SPEC = ROOT / "specs" / "rover.yaml"
WORLD = ROOT / "specs" / "rover" / "world.yaml"
DRIVE = ROOT / "specs" / "trajectories" / "rover" / "drive.yaml"
VARIANTS = {"bare": (), "lidar": ("base_scan",), "depth": ("front_depth",)}
TARGETS = {"lidar": 1.10, "depth": 1.50}


def spec_with(tmp: Path, sensors: tuple[str, ...]) -> Path:
    data = yaml.safe_load(SPEC.read_text())
    data["sensors"] = {k: v for k, v in data["sensors"].items() if k in sensors}
    path = tmp / f"rover_{'_'.join(sensors) or 'bare'}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def loop_cpu(job: drive.DriveJob) -> float:
    start = time.process_time()
    drive.run(job)
    return time.process_time() - start


def process_cpu(spec: Path, duration: float, out: Path) -> float:
    armcli = str(Path(sys.executable).parent / "armcli")
    cmd = [armcli, "simulate", str(spec), "--cmd-vel", str(DRIVE), "--world", str(WORLD),
           "--duration", str(duration), "-o", str(out)]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"failed: {' '.join(cmd)}")
    return usage.ru_utime + usage.ru_stime


def rounds(measure: dict[str, Any], n: int) -> dict[str, list[float]]:
    out: dict[str, list[float]] = {k: [] for k in measure}
    for _ in range(n):
        for k, f in measure.items():
            out[k].append(f())
    return out


def report(title: str, cpu: dict[str, list[float]]) -> None:
    """Per variant: the median per-round ratio (and its spread) and the ratio of the least
    CPU each took (on a loaded machine the least is the run least disturbed)."""
    print(f"\n{title}: CPU [s] median (least); ratio to the bare drive per round (min..max)")
    bare = cpu["bare"]
    for k in ("lidar", "depth"):
        ratios = [a / b for a, b in zip(cpu[k], bare, strict=True)]
        med, least = statistics.median(ratios), min(cpu[k]) / min(bare)
        verdict = "ok" if med <= TARGETS[k] else "OVER"
        print(f"  {k:6s} {statistics.median(cpu[k]):6.3f} ({min(cpu[k]):.3f}) vs bare "
              f"{statistics.median(bare):6.3f} ({min(bare):.3f}): x{med:.3f} "
              f"({min(ratios):.3f}..{max(ratios):.3f}), least/least x{least:.3f}; "
              f"target <= x{TARGETS[k]:.2f}: {verdict}")  # fmt: skip


def floors(tmp: Path, reps: int) -> None:
    """One scan and one depth image: the samplers against a Python loop of mj_ray."""
    import mujoco

    file = read_robot(spec_with(tmp, ("base_scan", "front_depth")))
    job = drive.prepare(file, SimOptions(duration=1.0), DRIVE, world=WORLD)
    spec = file.spec
    assert spec is not None
    m = job.model.model
    d = drive.start_data(job.model, job.arm.q0)
    for _ in range(500):
        mujoco.mj_step(m, d)
    lidar = scanners.LidarSampler("base_scan", spec.sensors["base_scan"], m, np.zeros(1, int))
    depth = scanners.DepthSampler("front_depth", spec.sensors["front_depth"], m, np.zeros(1, int))
    plain = scanners.DepthSampler("front_depth", spec.sensors["front_depth"], m, np.zeros(1, int))
    plain.native = None
    plain_lidar = scanners.LidarSampler("base_scan", spec.sensors["base_scan"], m, np.zeros(1, int))
    plain_lidar.geoms = None  # the mj_multiRay path

    def python_loop(s: Any) -> None:
        origin, R = d.site_xpos[s.site], d.site_xmat[s.site].reshape(3, 3)
        geom = np.zeros(1, dtype=np.int32)
        for v in s.dirs @ R.T:
            mujoco.mj_ray(m, d, origin, v, raycast.SEEN_GROUPS, 1, -1, geom)

    def step() -> None:
        mujoco.mj_step(m, d)

    slow = max(1, reps // 4)
    cases = {
        "one physics step": (step, 200),
        "lidar: sampler (compiled caster)": (lambda: lidar.sample(0, m, d), reps),
        "lidar: sampler without it (mj_multiRay)": (lambda: plain_lidar.sample(0, m, d), reps),
        "lidar: Python loop of mj_ray": (lambda: python_loop(lidar), reps),
        "depth: sampler (compiled caster)": (lambda: depth.sample(0, m, d), reps),
        "depth: sampler without it (mj_multiRay)": (lambda: plain.sample(0, m, d), slow),
        "depth: Python loop of mj_ray": (lambda: python_loop(depth), 1),
    }
    print("\none sample in a fixed state (CPU per call; x: in physics steps of this model)")
    per = {}
    for name, (f, n) in cases.items():
        f()
        start = time.process_time()
        for _ in range(n):
            f()
        per[name] = (time.process_time() - start) / n
    for name, t in per.items():
        print(f"  {name:42s} {t * 1e6:10.1f} µs  = {t / per['one physics step']:8.1f} steps")
    for kind in ("lidar", "depth"):
        fast = per[f"{kind}: sampler (compiled caster)"]
        loop = per[f"{kind}: Python loop of mj_ray"] / fast
        multi = per[f"{kind}: sampler without it (mj_multiRay)"] / fast
        share = 100 * fast / (per["one physics step"] * 100)  # 10 Hz at 1 ms: 1 per 100 steps
        print(
            f"  {kind}: the sampler beats the Python loop x{loop:.1f}, mj_multiRay "
            f"x{multi:.1f}; at 10 Hz and 1 ms it adds {share:.1f} % to the stepping"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer, shorter rounds")
    args = ap.parse_args()
    duration, n = (4.0, 2) if args.quick else (12.0, 5)
    print(f"bench_sensors: load {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs; {duration:g} s "
          f"drives of {SPEC.name} among {WORLD.parent.name}/{WORLD.name}, {n} rounds")  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp_:
        tmp = Path(tmp_)
        specs = {k: spec_with(tmp, v) for k, v in VARIANTS.items()}
        jobs = {k: drive.prepare(read_robot(p), SimOptions(duration=duration), DRIVE, world=WORLD)
                for k, p in specs.items()}  # fmt: skip
        report(
            "the run (drive.job.run)",
            rounds({k: (lambda j=j: loop_cpu(j)) for k, j in jobs.items()}, n),
        )
        out = tmp / "run.mcap"
        procs = {k: (lambda p=p: process_cpu(p, duration, out)) for k, p in specs.items()}
        report("the command (armcli simulate ... -o run.mcap, whole process)", rounds(procs, n))
        floors(tmp, 5 if args.quick else 20)
    print(f"load after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
