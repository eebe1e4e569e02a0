"""Benchmark: what the static balance and reach analysis adds to `armcli check`.

Side by side, in turn (A B A B ...), fresh processes each running `armcli check SPEC`
(default: specs/my_robot.yaml, both its URDFs) through the real command, output thrown
away: A with every rule family, B with the families `tipover` (support polygon, COM
margins, tipping angles, worst over the joint range, payload), `reach` (envelope) and
`zmp` (idle without --trajectory) and the report's balance lines replaced by no-ops
before anything is imported, so B pays none of their imports either (the child checks
that none of their modules was loaded). Whole-process wall time from the interpreter's
start, and CPU time (user + system: steadier on a loaded machine); the median of the
pairwise CPU differences A - B is what the analysis adds (issue 22: under 0.3 s).
Run `python bench/bench_check_balance.py [-n 7] [SPEC]`. Not a test: numbers depend on
the machine and its load (printed).
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OFF = ("armcli.check.tipover", "armcli.check.zmp", "armcli.check.reach")
REPORT = "armcli.check.balance_report"
THEIRS = (  # loaded only for the balance and reach families
    "armcli.analysis.balance",
    "armcli.analysis.stance",
    "armcli.analysis.ground",
    "armcli.analysis.support",
    "armcli.analysis.workspace",
    "armcli.analysis.boxsearch",
    "armcli.analysis.zmp",
    "armcli.sim.tipping",
)
BUDGET_S = 0.3  # [s] the bound


def child(mode: str, spec: str) -> None:
    """One `armcli check SPEC` in this process; prints its wall time from interpreter start."""
    if mode == "without":
        import types

        for name in OFF:
            stub = types.ModuleType(name)
            stub.check = lambda c: None  # type: ignore[attr-defined]
            sys.modules[name] = stub
        report = types.ModuleType(REPORT)
        report.balance_items = lambda *a: []  # type: ignore[attr-defined]
        report.reach_items = lambda *a: []  # type: ignore[attr-defined]
        sys.modules[REPORT] = report
    from armcli.cli import main

    devnull = open(os.devnull, "w")  # noqa: SIM115
    sys.stdout = devnull
    try:
        main(["check", spec])
    except SystemExit as exc:
        code = exc.code
    sys.stdout = sys.__stdout__
    leaked = [m for m in THEIRS if m in sys.modules] if mode == "without" else []
    wall = time.time() - float(os.environ.get("BENCH_T0", "nan"))
    ru = resource.getrusage(resource.RUSAGE_SELF)
    print(f"{wall:.6f} {ru.ru_utime + ru.ru_stime:.6f} {code} {','.join(leaked) or '-'}")


def run_once(mode: str, spec: str) -> tuple[float, float]:
    """(wall, cpu) seconds of one child from the interpreter's start."""
    env = {**os.environ, "BENCH_T0": repr(time.time())}
    out = subprocess.run(
        [sys.executable, __file__, "--child", mode, spec],
        capture_output=True, text=True, check=True, env=env, cwd=ROOT,
    ).stdout.split()  # fmt: skip
    wall, cpu, code, leaked = float(out[0]), float(out[1]), out[2], out[3]
    if leaked != "-":
        raise SystemExit(f"B loaded the balance modules anyway: {leaked}")
    if code not in ("0", "None"):
        raise SystemExit(f"check exited {code} in mode {mode}")
    return wall, cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec", nargs="?", default="specs/my_robot.yaml")
    ap.add_argument("-n", type=int, default=7, help="pairs (after one warm-up pair)")
    ap.add_argument("--child", choices=("with", "without"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args.child, args.spec)
        return
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; spec {args.spec}")
    run_once("with", args.spec), run_once("without", args.spec)  # warm the file cache
    a: list[tuple[float, float]] = []
    b: list[tuple[float, float]] = []
    for _ in range(args.n):
        a.append(run_once("with", args.spec))
        b.append(run_once("without", args.spec))
    print(f"{'':34}{'median':>8}{'min':>8}{'max':>8}")
    med = {}
    for k, what in enumerate(("wall", "cpu")):
        xa, xb = [r[k] for r in a], [r[k] for r in b]
        d = [x - y for x, y in zip(xa, xb, strict=True)]
        for label, xs in ((f"A  every family ({what})", xa), (f"B  no balance/reach ({what})", xb),
                          (f"A - B pairwise ({what})", d)):  # fmt: skip
            print(f"{label:34}{statistics.median(xs):8.3f}{min(xs):8.3f}{max(xs):8.3f} s")
        med[what] = (statistics.median(d), statistics.median(xa) / statistics.median(xb))
        print(f"{'':34}A / B = {med[what][1]:.3f}")
    med_d = med["cpu"][0]  # CPU time: what the analysis costs, whatever the machine's load
    verdict = "within" if med_d < BUDGET_S else "OVER"
    print(f"{verdict} the issue's budget of {BUDGET_S} s (CPU time added: {med_d:.3f} s)")


if __name__ == "__main__":
    main()
