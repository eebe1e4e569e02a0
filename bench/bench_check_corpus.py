"""Benchmark: `armcli check` CPU per real robot description, beside urdf_validate.

    python bench/bench_check_corpus.py [--files LIST] [--limit N] [--per-file] [--src DIR]

The corpus: every URDF example-robot-data installs (the dev extra; 69 public robots from
a double pendulum to Talos), plus the files named in LIST (one path per line, then any
xacro arguments; lines starting with # skipped), e.g. ROS 2 descriptions fetched for a
local run. Each file is checked in a fresh process as CI runs it (`python -m armcli.cli
check FILE --format json`), and the peer, urdf-validator's `urdf_validate FILE` (pip
urdf-validator, the physics-aware validator in the same space: inertia, statics,
stability, workspace), on the same file in the same run. CPU is user + system time of
the child process (RUSAGE_CHILDREN), so other jobs on the machine change it less than
wall time. `--src` times another checkout's armcli (a "before" run). Prints the per-file
median, the 90th percentile, the largest, and the ratio of the medians. Not a test: the
numbers depend on the machine and its load (printed).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT_S = 300.0


def corpus(files: Path | None) -> list[tuple[Path, list[str]]]:
    """example-robot-data's URDFs, then LIST's entries (path, xacro arguments)."""
    out: list[tuple[Path, list[str]]] = []
    try:
        dist = importlib.metadata.distribution("example-robot-data")
        found = (Path(str(dist.locate_file(f))) for f in dist.files or ())
        out += [(p, []) for p in sorted(found) if p.suffix == ".urdf" and "/robots/" in str(p)]
    except importlib.metadata.PackageNotFoundError:
        print("example-robot-data is not installed (pip install -e '.[dev]')")
    if files is not None:
        for row in files.read_text().splitlines():
            if row.strip() and not row.startswith("#"):
                path, *args = row.split()
                out.append((Path(path), args))
    return out


def cpu_of(argv: list[str], env: dict[str, str]) -> tuple[float, int]:
    """(CPU seconds of the child, its exit code); -1 on a timeout."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        code = subprocess.run(
            argv, env=env, capture_output=True, timeout=TIMEOUT_S, check=False
        ).returncode
    except subprocess.TimeoutExpired:
        code = -1
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, code


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--files", type=Path, help="more descriptions: one path (+ args) a line")
    ap.add_argument("--limit", type=int, default=0, help="only the first N files")
    ap.add_argument("--per-file", action="store_true", help="print every file's numbers")
    ap.add_argument("--src", type=Path, default=ROOT / "src", help="armcli source to time")
    opts = ap.parse_args()
    entries = corpus(opts.files)[: opts.limit or None]
    peer = shutil.which("urdf_validate") or str(Path(sys.executable).parent / "urdf_validate")
    have_peer = Path(peer).is_file()
    env = {**os.environ, "PYTHONPATH": str(opts.src)}
    print(f"load average {os.getloadavg()[0]:.1f}; {len(entries)} files")
    ours: list[float] = []
    theirs: list[float] = []
    with tempfile.TemporaryDirectory() as tmp:
        for path, args in entries:
            cmd = [sys.executable, "-m", "armcli.cli", "check", str(path), *args]
            mine, code = cpu_of([*cmd, "--format", "json"], env)
            ours.append(mine)
            line = f"{mine:6.2f} s armcli (exit {code})"
            if have_peer and path.suffix == ".urdf":
                peer_cpu, peer_code = cpu_of([peer, str(path), "--output-dir", tmp], env)
                theirs.append(peer_cpu)
                line += f"  {peer_cpu:6.2f} s urdf_validate (exit {peer_code})"
            if opts.per_file:
                print(f"{line}  {path.name} {' '.join(args)}", flush=True)
    if not ours:
        return 0
    _summary("armcli check", ours)
    if theirs:
        _summary("urdf_validate", theirs)
        ratio = statistics.median(ours) / statistics.median(theirs)
        print(f"median ratio armcli / urdf_validate: {ratio:.2f}")
    return 0


def _summary(name: str, cpu: list[float]) -> None:
    s = sorted(cpu)
    p90 = s[min(len(s) - 1, int(0.9 * len(s)))]
    print(
        f"{name:14s} CPU per file: median {statistics.median(s):.2f} s, 90th percentile "
        f"{p90:.2f} s, max {s[-1]:.2f} s, total {sum(s):.1f} s over {len(s)} files"
    )


if __name__ == "__main__":
    sys.exit(main())
