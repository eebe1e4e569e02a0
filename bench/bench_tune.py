"""Benchmark: `armcli tune` candidates per second on each backend, and a projection.

Run with `make bench` (or `python bench/bench_tune.py [--quick]`). Scores the same seeded
set of candidate gains for the seed arm on its three example trajectories with: one
thread, `--jobs 2` (thread pool), and a two-worker `distributed.LocalCluster` (worker
processes, one thread each). Prints candidates/s (median of repeats, after a warm-up that
builds the models), the ratio to one thread, checks that every backend returned the same
costs, and projects a 1,000-candidate robust tuning (`--robust 8`) on 100 cores from the
one-thread rate, the measured two-worker Dask efficiency and the measured driver-side
TPE sampling time (serial: it does not scale with cores). Not a test: numbers depend
on the machine and its load.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from armcli.sim import native  # noqa: E402
from armcli.tune import job as tjob  # noqa: E402
from armcli.tune.engine import DaskEngine, Engine, LocalEngine  # noqa: E402
from armcli.tune.objective import Weights  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402

SPEC = ROOT / "specs" / "my_robot.yaml"
SEED = 0
PROJECT_CANDIDATES = 1000
PROJECT_ROBUST = 8  # perturbed models per candidate in the projection
PROJECT_CORES = 100


def candidates(job: tjob.TuneJob, count: int) -> list[np.ndarray]:
    """Start gains times seeded log-uniform factors in [1/2, 2] (all stable at dt)."""
    rng = np.random.default_rng(SEED)
    start = np.concatenate([job.start.kp, job.start.kd])
    return [start * np.exp(rng.uniform(-np.log(2), np.log(2), start.size)) for _ in range(count)]


def cpu_seconds() -> float:
    """CPU seconds (user + system) of this process and its children, alive or reaped:
    the driver, its threads and a local cluster's scheduler and worker processes."""
    import psutil

    me = psutil.Process()
    total = sum(me.cpu_times()[:2])
    for child in me.children(recursive=True):
        with contextlib.suppress(psutil.NoSuchProcess):  # exited between the two calls
            total += sum(child.cpu_times()[:2])
    return total


def measure(
    engines: list[Engine], job: tjob.TuneJob, batch: list[np.ndarray], repeats: int
) -> list[tuple[list[float], list[float], list]]:
    """Per engine: wall seconds and CPU seconds of each repeat, and the costs. The engines
    take turns (A B C A B C ...), so a change in the machine's load hits all of them."""
    for engine in engines:
        engine.evaluate(job.problem, batch[:4], Weights())  # warm-up: models, scatter, imports
    out: list[tuple[list[float], list[float], list]] = [([], [], []) for _ in engines]
    for _ in range(repeats):
        for engine, (walls, cpus, costs) in zip(engines, out, strict=True):
            c0, t0 = cpu_seconds(), time.perf_counter()
            evs = engine.evaluate(job.problem, batch, Weights())
            walls.append(time.perf_counter() - t0)
            cpus.append(cpu_seconds() - c0)
            costs[:] = [ev.costs.tolist() for ev in evs]
    return out


def sampler_seconds(params: int, trials: int, batch: int) -> float:
    """Driver-side TPE time (ask + tell) for `trials` in batches, on a cheap objective."""
    import optuna

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    dists: dict[str, optuna.distributions.BaseDistribution] = {
        f"g{i}": optuna.distributions.FloatDistribution(0.1, 10.0, log=True) for i in range(params)
    }
    study = optuna.create_study(sampler=optuna.samplers.TPESampler(seed=SEED))
    t0 = time.perf_counter()
    for _ in range(trials // batch):
        asked = [study.ask(dists) for _ in range(batch)]
        for t in asked:
            study.tell(t, float(sum(np.log(v) ** 2 for v in t.params.values())))
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer candidates and repeats")
    args = ap.parse_args()
    count, repeats = (8, 2) if args.quick else (32, 7)
    native.require()
    job = tjob.prepare(read_robot(SPEC), [], tjob.TuneSettings())
    batch = candidates(job, count)
    steps = sum(round(c.duration / job.problem.dt) for c in job.problem.cases)
    print(f"load average before the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"seed arm, {len(job.problem.cases)} trajectories, {steps} steps per candidate, "
          f"{count} candidates x {repeats} repeats")  # fmt: skip
    from distributed import LocalCluster

    labels = ["1 thread", "--jobs 2 (threads)", "Dask LocalCluster, 2 worker processes"]
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0", host="127.0.0.1") as cluster:  # fmt: skip
        engines: list[Engine] = [
            LocalEngine(1),
            LocalEngine(2),
            DaskEngine(cluster.scheduler_address),
        ]
        try:
            got = measure(engines, job, batch, repeats)
        finally:
            for engine in engines:
                engine.close()
    print(f"load average after the run: {os.getloadavg()[0]:.1f}")
    # best of the repeats: a loaded machine only ever adds time; the median shows the spread
    rows = [(label, count / min(w), count / statistics.median(w), statistics.median(c) / count,
             costs) for label, (w, c, costs) in zip(labels, got, strict=True)]  # fmt: skip
    base, base_median, base_cpu = rows[0][1], rows[0][2], rows[0][3]
    print(f"{'backend':40s} {'cand./s best':>12s} {'vs 1 thread':>11s} {'median':>8s} "
          f"{'CPU ms/cand.':>12s} {'same costs':>10s}")  # fmt: skip
    for label, best, med, cpu, costs in rows:
        print(f"{label:40s} {best:12.1f} {best / base:10.2f}x {med / base_median:7.2f}x "
              f"{cpu * 1e3:12.1f} {costs == rows[0][4]!s:>10s}")  # fmt: skip
    print(f"CPU per candidate vs 1 thread: threads {rows[1][3] / base_cpu:.2f}x, "
          f"Dask {rows[2][3] / base_cpu:.2f}x (all processes; 2 / that bounds the scaling "
          f"on 2 idle cores)")  # fmt: skip
    efficiency = rows[2][1] / (2 * base)
    per_core = base * efficiency
    compute = PROJECT_CANDIDATES * PROJECT_ROBUST / (per_core * PROJECT_CORES)
    sampler = sampler_seconds(2 * len(job.problem.joints), PROJECT_CANDIDATES, PROJECT_CORES)
    print(
        f"projection: {PROJECT_CANDIDATES} candidates x --robust {PROJECT_ROBUST} on "
        f"{PROJECT_CORES} cores, --batch {PROJECT_CORES}: "
        f"{PROJECT_CANDIDATES * PROJECT_ROBUST} candidate-model scores at {base:.1f}/s/core "
        f"x {efficiency:.2f} (2-worker Dask efficiency) = {compute:.1f} s of rollouts "
        f"+ {sampler:.1f} s of TPE sampling on the driver (measured) = {compute + sampler:.1f} s"
    )


if __name__ == "__main__":
    main()
