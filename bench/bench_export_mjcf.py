"""Benchmark: `armcli export mjcf` vs MuJoCo's own URDF import, same URDF.

Run with `python bench/bench_export_mjcf.py [--quick]`. The peer is what a MuJoCo user
does without armcli: `MjModel.from_xml_string(urdf)` then `mj_saveLastXML`. Both start
from the URDF text already in memory (the spec -> URDF build through xacro is common to
both and not timed). Prints ms per export (median of repeats) and the ratio. Not a
test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import mujoco  # noqa: E402

from armcli.export.mjcf import build_mjcf  # noqa: E402
from armcli.spec.load import load_spec  # noqa: E402
from armcli.urdf.source import read_robot  # noqa: E402


def median_ms(fn: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true")
    repeats = 5 if ap.parse_args().quick else 50
    print(f"{'spec / document':40} {'armcli [ms]':>12} {'MuJoCo [ms]':>12} {'ratio':>7}")
    for spec_path in sorted((ROOT / "specs").glob("*.yaml")):
        spec = load_spec(spec_path)
        for urdf in read_robot(spec_path).urdfs:
            text = urdf.text.decode()
            with tempfile.TemporaryDirectory() as tmp:
                out = str(Path(tmp) / "m.xml")

                def peer(text: str = text, out: str = out) -> None:
                    mujoco.mj_saveLastXML(out, mujoco.MjModel.from_xml_string(text))

                ours = median_ms(lambda u=urdf, s=spec: build_mjcf(u, s), repeats)
                theirs = median_ms(peer, repeats)
            name = f"{spec_path.stem} / {urdf.source.split('#')[-1]}"
            print(f"{name:40} {ours:12.2f} {theirs:12.2f} {ours / theirs:7.2f}")


if __name__ == "__main__":
    main()
