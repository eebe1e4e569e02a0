"""Benchmark: `armcli export mjcf` vs MuJoCo's own URDF import, and over real robots.

Run with `python bench/bench_export_mjcf.py [--quick]`. The peer is what a MuJoCo user
does without armcli: `MjModel.from_xml_string(urdf)` then `mj_saveLastXML`. Both start
from the URDF text already in memory (the spec -> URDF build through xacro is common to
both and not timed). Prints ms per export (median of repeats) and the ratio. Not a
test: numbers depend on the machine and its load.

`--corpus DIR` (e.g. /work/corpus, see its README) instead runs the CLI as a user with a
sourced ROS 2 workspace (AMENT_PREFIX_PATH=DIR/install) on every `*.urdf` under DIR/src
and on real_descriptions.py's xacro entries when that script is beside this one, loads
what it wrote with MuJoCo, and counts: written and loaded by MuJoCo, written (exit 0)
but refused by MuJoCo (the failure issue 19 forbids), refused by armcli with a reason.
`--armcli-src SRC` runs another checkout's armcli (PYTHONPATH=SRC) for a "before" count.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections import Counter
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


def corpus_entries(corpus: Path) -> list[tuple[str, Path, tuple[str, ...]]]:
    """(label, file, xacro arguments): every plain URDF, then the xacro entry points."""
    src = corpus / "src"
    out = [(str(p.relative_to(src)), p, ()) for p in sorted(src.rglob("*.urdf"))]
    try:
        sys.path.insert(0, str(ROOT / "bench"))
        from real_descriptions import ENTRIES  # type: ignore[import-not-found]
    except ImportError:
        return out
    xacros = [e for e in ENTRIES if not e.path.endswith(".urdf")]
    return out + [(e.label, src / e.path, tuple(e.args)) for e in xacros]


# Runs the armcli under SRC (argv[1]) even where an editable install's import hook
# would hand out this checkout's.
BOOT = (
    "import runpy, sys\n"
    "sys.meta_path[:] = [f for f in sys.meta_path if 'Redirect' not in type(f).__name__]\n"
    "sys.path.insert(0, sys.argv.pop(1))\n"
    "runpy.run_module('armcli', run_name='__main__')\n"
)


def export_one(
    path: Path, args: tuple[str, ...], env: dict[str, str], src: Path
) -> tuple[str, str]:
    """(outcome, first line of the reason): loaded | mujoco-refused | refused."""
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [sys.executable, "-c", BOOT, str(src), "export", "mjcf", str(path), *args]
        r = subprocess.run(
            [*cmd, "-o", f"{tmp}/robot.xml"], env=env, capture_output=True, text=True, timeout=600
        )
        if r.returncode != 0:
            return "refused", (r.stderr.strip().splitlines() or ["?"])[-1][:160]
        try:
            mujoco.MjModel.from_xml_path(f"{tmp}/scene.xml")
        except ValueError as exc:
            return "mujoco-refused", str(exc).splitlines()[0][:160]
    return "loaded", ""


def run_corpus(corpus: Path, armcli_src: Path | None) -> None:
    env = {**os.environ, "AMENT_PREFIX_PATH": str(corpus / "install")}
    env.pop("ROS_PACKAGE_PATH", None)
    counts: Counter[str] = Counter()
    for label, path, args in corpus_entries(corpus):
        outcome, why = export_one(path, args, env, armcli_src or ROOT / "src")
        counts[outcome] += 1
        print(f"{outcome:15} {label} {' '.join(args)}  {why}", flush=True)
    total = sum(counts.values())
    print(f"\n{total} models: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--corpus", type=Path, help="a directory with src/ and install/")
    ap.add_argument("--armcli-src", type=Path, help="another checkout's src/ (before)")
    opts = ap.parse_args()
    if opts.corpus:
        run_corpus(opts.corpus, opts.armcli_src)
        return
    repeats = 5 if opts.quick else 50
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
