"""Benchmark: the spec's own expansion (safe evaluator) vs real xacro, and parts scaling.

Run with `python bench/bench_build_expand.py [--quick]`. Issue 27 moved `armcli build`'s
expansion from xacro's Python `eval` to armcli's safe evaluator; the peer is
`xacro.process_file` on the same generated set, in this process. The second table loads
and builds a spec of N links placed as parts of a fixed-joint chain, beside the same robot
written out flat (the peer), for N = 60 and 240: linear work keeps the ratio flat.
Prints ms (median of repeats) and ratios. Not a test: numbers depend on the machine.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import xacro  # noqa: E402

from armcli.compiler.expand import expand_urdfs  # noqa: E402
from armcli.compiler.xacro_writer import top_level_files, xacro_files  # noqa: E402
from armcli.spec.load import load_spec, loads_spec  # noqa: E402

BOX = "{geometry: {box: {size: [0.01, 0.01, 0.01]}}, mass: 0.1}"


def median_ms(fn: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1000 * statistics.median(times)


def real_xacro(spec: object) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        for name, data in xacro_files(spec).items():  # type: ignore[arg-type]
            (Path(tmp) / name).write_bytes(data)
        for top in top_level_files(spec).values():  # type: ignore[arg-type]
            with contextlib.redirect_stderr(io.StringIO()):
                xacro.process_file(str(Path(tmp) / top))


def parts_spec(per_part: int, placements: int) -> str:
    out = ["name: b", "parts:", "  seg:", "    links:"]
    out += [f"      l{i}: {BOX}" for i in range(per_part)]
    out += ["    joints:"] + [
        f"      j{i}: {{type: fixed, parent: l{i - 1}, child: l{i}}}" for i in range(1, per_part)
    ]
    out += ["arm:", "  links:", f"    base_link: {BOX}", "  joints: {}", "  parts:"]
    out += [
        f"    - {{part: seg, prefix: p{k}_, parent: base_link, joint: a{k}}}"
        for k in range(placements)
    ]
    return "\n".join(out) + "\n"


def flat_spec(per_part: int, placements: int) -> str:
    out = ["name: b", "arm:", "  links:", f"    base_link: {BOX}"]
    out += [f"    p{k}_l{i}: {BOX}" for k in range(placements) for i in range(per_part)]
    out.append("  joints:")
    for k in range(placements):
        out.append(f"    a{k}: {{type: fixed, parent: base_link, child: p{k}_l0}}")
        out += [
            f"    p{k}_j{i}: {{type: fixed, parent: p{k}_l{i - 1}, child: p{k}_l{i}}}"
            for i in range(1, per_part)
        ]
    return "\n".join(out) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    repeats = 3 if parser.parse_args().quick else 9
    spec = load_spec(ROOT / "specs" / "my_robot.yaml")
    safe = median_ms(lambda: expand_urdfs(spec), repeats)
    peer = median_ms(lambda: real_xacro(spec), repeats)
    print(f"my_robot expansion: safe {safe:.1f} ms, real xacro {peer:.1f} ms, "
          f"ratio {safe / peer:.2f}")  # fmt: skip
    for n in (60, 240):
        parts = median_ms(lambda n=n: expand_urdfs(loads_spec(parts_spec(30, n // 30))), repeats)
        flat = median_ms(lambda n=n: expand_urdfs(loads_spec(flat_spec(30, n // 30))), repeats)
        print(f"{n} links: parts {parts:.1f} ms, flat {flat:.1f} ms, ratio {parts / flat:.2f}")


if __name__ == "__main__":
    main()
