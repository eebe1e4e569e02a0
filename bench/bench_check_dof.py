"""Benchmark: `armcli check`'s PD stability analysis against the number of joints.

Chains of N revolute joints (30, 60, 120 and 128, the documented limit) are written as
specs into a temporary directory. Per N it prints the whole `armcli check` process (a
fresh process, as CI runs it) and the stability analysis alone (`armcli.analysis.verdict.analyse`
on check's own samples), beside the eigenvalue computation it replaced
(tests/analysis/stability_reference.py: spectral radius of the 2n x 2n step map at every
sample, bisection on it for the largest stable dt) on the same samples, up to
`--reference-dof` joints (default 30: above that the old computation takes minutes), and
the ratio. Run with `make bench` or `python bench/bench_check_dof.py`. Not a test:
numbers depend on the machine and its load (printed).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "src"), str(ROOT)]

from tests.analysis import stability_reference as ref  # noqa: E402

from armcli.analysis import pdloop  # noqa: E402
from armcli.analysis import verdict as verdicts  # noqa: E402
from armcli.compiler.expand import expand_urdfs  # noqa: E402
from armcli.defaults import STANDALONE_ARM_URDF  # noqa: E402
from armcli.robot import sampling  # noqa: E402
from armcli.robot.model import Robot  # noqa: E402
from armcli.spec.load import load_spec  # noqa: E402
from armcli.urdf.read import parse_urdf  # noqa: E402

DOFS = (30, 60, 120, 128)
KP, KD, DAMPING, DT = 5.0, 0.05, 0.01, 1e-3


def chain_spec(n: int) -> str:
    """A spec of n 5 cm links, joints alternating about y and x, PD on every joint."""
    lines = [
        f"name: chain{n}", "materials:",
        "  grey: {rgba: [0.5, 0.5, 0.5, 1.0], gazebo: Gazebo/Grey}",
        "arm:", "  links:", "    base_link: {}",
    ]  # fmt: skip
    for i in range(n):
        lines += [f"    link{i}:", "      geometry: {cylinder: {radius: 0.01, length: 0.05}}",
                  "      origin: {xyz: [0, 0, 0.025]}", "      material: grey",
                  "      mass: 0.05"]  # fmt: skip
    lines.append("  joints:")
    for i in range(n):
        parent = "base_link" if i == 0 else f"link{i - 1}"
        axis = "[0, 1, 0]" if i % 2 == 0 else "[1, 0, 0]"
        lines += [f"    joint{i}:", "      type: revolute", f"      parent: {parent}",
                  f"      child: link{i}",
                  f"      origin: {{xyz: [0, 0, {0.0 if i == 0 else 0.05}]}}",
                  f"      axis: {axis}",
                  "      limit: {lower: -0.5, upper: 0.5, effort: 1000, velocity: 10}",
                  f"      dynamics: {{friction: 0.0, damping: {DAMPING}}}"]  # fmt: skip
    lines += [f"  tool: {{link: link{n - 1}}}", "control:", f"  dt: {DT}", "  gains:"]
    lines += [f"    joint{i}: {{kp: {KP}, kd: {KD}}}" for i in range(n)]
    return "\n".join(lines) + "\n"


def analysis_seconds(spec_path: Path, with_reference: bool) -> tuple[float, float | None]:
    """The stability analysis on check's samples: new, and the old eigenvalue computation."""
    spec = load_spec(spec_path)
    xml = expand_urdfs(spec)[STANDALONE_ARM_URDF].decode()
    robot = Robot.load(parse_urdf(xml.encode(), STANDALONE_ARM_URDF), strict=False)
    model, ranges = robot.model, robot.joints
    samples = sampling.configurations(robot)
    n = model.nv
    t0 = time.perf_counter()
    lin = pdloop.linearise(robot, [q for _, q in samples])
    pd = pdloop.PD.of(range(n), [KP] * n, [KD] * n, [DAMPING] * n)
    verdicts.analyse(lin, [[p[r.name] for r in ranges] for p, _ in samples], pd, DT)
    new = time.perf_counter() - t0
    if not with_reference:
        return new, None
    t0 = time.perf_counter()
    lin = pdloop.linearise(robot, [q for _, q in samples], gravity=False)  # M only, as before
    Ms, Gs = list(lin.M), list(lin.G)
    kp, d = np.full(n, KP), np.full(n, KD + DAMPING)
    for scheme in ("explicit", "implicit"):
        ref.worst_radius(Ms, Gs, range(n), kp, d, DT, scheme)
        ref.largest_stable_dt(Ms, Gs, range(n), kp, d, scheme, DT)
    return new, time.perf_counter() - t0


def process_seconds(spec_path: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run(
        [str(Path(sys.executable).parent / "armcli"), "check", str(spec_path)],
        capture_output=True, check=False,
    )  # fmt: skip
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference-dof", type=int, default=30, help="old computation up to N")
    args = ap.parse_args()
    print(f"load average before the run: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'DoF':>4s} {'check process':>14s} {'analysis':>9s} {'eigenvalues':>12s} {'ratio':>7s}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in DOFS:
            path = Path(tmp) / f"chain{n}.yaml"
            path.write_text(chain_spec(n))
            whole = process_seconds(path)
            new, old = analysis_seconds(path, n <= args.reference_dof)
            old_txt = f"{old:11.2f}s" if old is not None else f"{'-':>12s}"
            ratio = f"{old / new:6.0f}x" if old is not None else f"{'-':>7s}"
            print(f"{n:4d} {whole:13.2f}s {new:8.2f}s {old_txt} {ratio}")
    print(f"load average after the run: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
