"""Benchmark: foreign xacro expansion in armcli's three modes vs xacro itself.

Run with `python bench/bench_xacro.py [--quick]`. The peer is plain
`xacro.process_file` in this process (what a ROS user runs, with no protection).
armcli's modes: safe mode in process (`expand_safe`, the AST-whitelisted evaluator),
safe mode as the CLI runs it (in the limited child process), `--trust-xacro` (xacro in
the bubblewrap sandbox) and `--trust-xacro=unsandboxed` (xacro in the limited child).
Input: the course macros fixture and armcli's own `my_robot.urdf.xacro` set. Prints
ms per expansion (median of repeats) and the ratio to the peer. Not a test: numbers
depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import xacro  # noqa: E402
from armcli.xacro.jail import sandbox_problem  # noqa: E402
from armcli.xacro.safe import expand_safe  # noqa: E402
from armcli.xacro.sandbox import expand_foreign, expand_untrusted  # noqa: E402

FILES = (
    ROOT / "tests" / "fixtures" / "check" / "course_macros.urdf.xacro",
    ROOT / "urdf" / "my_robot.urdf.xacro",
)


def median_ms(fn: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    repeats = 3 if ap.parse_args().quick else 15
    for path in FILES:
        peer = median_ms(lambda p=path: xacro.process_file(str(p)).toprettyxml(), repeats)
        modes: dict[str, Callable[[], object]] = {
            "safe, in process": lambda p=path: expand_safe(p, [p.parent]),
            "safe, child (CLI)": lambda p=path: expand_foreign(p, [p.parent]),
            "--trust-xacro=unsandboxed": lambda p=path: expand_untrusted(p, unsandboxed=True),
        }
        if sandbox_problem() is None:
            modes["--trust-xacro (bubblewrap)"] = lambda p=path: expand_untrusted(p)
        print(f"{path.name}: xacro.process_file {peer:.1f} ms")
        for name, fn in modes.items():
            ms = median_ms(fn, repeats)
            print(f"  {name:28s} {ms:8.1f} ms  x{ms / peer:.2f}")


if __name__ == "__main__":
    main()
