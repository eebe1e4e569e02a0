"""`armcli import` then build on real robots: how many round-trip, checked two ways.

For every entry of `real_descriptions.ENTRIES` and every example-robot-data URDF under the
corpus: expand it (`armcli expand`, a sourced workspace's AMENT_PREFIX_PATH), import the
URDF (`import_urdf`, no start gains), build the spec, and compare the rebuilt URDF with
the original
- by the import's own comparison (`compare_urdf`: links, joints, inertials, geometry,
  materials, Gazebo and ros2_control blocks), and
- independently, by Pinocchio: the same joints in the same order with the same types,
  placements, limits, damping/friction, and the same body inertias (1e-9 relative).

    python bench/import_corpus.py /work/corpus [--only UR5e] [--json out.json]

CPU: about 1-3 s per robot; run it once, niced, for the numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from real_descriptions import ENTRIES, Entry

RTOL = 1e-9
# Clearpath's ROS 2 platforms (the A200 is the Husky, the J100 the Jackal) are macros: a
# two-line robot file calls each, as clearpath_platform_description's users do.
PLATFORM = "clearpath_common/clearpath_platform_description/urdf/{0}/{0}.urdf.xacro"
WRAPPED = [
    Entry("Clearpath A200 (Husky)", PLATFORM.format("a200")),
    Entry("Clearpath A200 (Husky), is_sim", PLATFORM.format("a200"), ("is_sim:=true",)),
    Entry("Clearpath J100 (Jackal)", PLATFORM.format("j100")),
    Entry("Clearpath J100 (Jackal), is_sim", PLATFORM.format("j100"), ("is_sim:=true",)),
    Entry("Clearpath W200", PLATFORM.format("w200")),
]
WRAPPER = """<?xml version="1.0"?>
<robot name="{macro}" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{path}"/>
  <xacro:{macro}/>
</robot>
"""


@dataclass
class Row:
    """What the import made of one robot."""

    label: str
    stage: str = ""  # "expand", "import", "build" when it stopped there, else "ok"
    error: str = ""
    differences: list[str] = field(default_factory=list)
    pinocchio: str = ""  # "same", "differs: ...", or why it could not compare
    passthrough: int = 0


def _close(a: Any, b: Any) -> bool:
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    finite = np.isfinite(x) & np.isfinite(y)
    with np.errstate(invalid="ignore"):
        diff = np.where(finite, x - y, 0.0)
    same_inf = ~finite & (x == y)
    scale = max(1.0, float(np.max(np.abs(np.where(finite, x, 0.0)), initial=0.0)))
    ok = np.abs(diff) <= RTOL * scale
    return bool(np.all(ok & (finite | same_inf)))


def pinocchio_difference(a: bytes, b: bytes) -> str:
    """'same', or the first difference of the two URDFs' Pinocchio models."""
    import pinocchio as pin

    try:
        ma = pin.buildModelFromXML(a.decode())
        mb = pin.buildModelFromXML(b.decode())
    except Exception as exc:  # any parser failure is reported, not raised
        return f"not loadable: {type(exc).__name__}: {str(exc)[:120]}"
    if list(ma.names) != list(mb.names):
        return f"joints {list(ma.names)[:4]}... vs {list(mb.names)[:4]}..."
    for i in range(ma.njoints):
        name = ma.names[i]
        if ma.joints[i].shortname() != mb.joints[i].shortname():
            return f"joint {name} type"
        if not _close(ma.jointPlacements[i].homogeneous, mb.jointPlacements[i].homogeneous):
            return f"joint {name} placement"
        ia, ib = ma.inertias[i], mb.inertias[i]
        if not (_close(ia.mass, ib.mass) and _close(ia.lever, ib.lever)):
            return f"body {name} mass/centre"
        if not _close(ia.inertia, ib.inertia):
            return f"body {name} inertia"
    for attr in ("lowerPositionLimit", "upperPositionLimit", "effortLimit", "velocityLimit",
                 "damping", "friction"):  # fmt: skip
        if not _close(getattr(ma, attr), getattr(mb, attr)):
            return attr
    return "same"


def _expand(path: Path, args: tuple[str, ...], env: dict[str, str], cwd: Path) -> bytes:
    if path.suffix != ".xacro":
        return path.read_bytes()
    if path.as_posix().endswith(tuple(e.path for e in WRAPPED)):
        macro = path.name.split(".")[0]
        path = cwd / f"{macro}_robot.urdf.xacro"
        path.write_text(WRAPPER.format(macro=macro, path=path_of(macro)))
    argv = [sys.executable, "-m", "armcli.cli", "expand", str(path), *args]
    proc = subprocess.run(argv, capture_output=True, env=env, cwd=cwd, check=False, timeout=300)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.decode("utf-8", "replace").strip().splitlines()[-1])
    return proc.stdout


def path_of(macro: str) -> str:
    """The wrapped macro file, found as the user's robot file would: through $(find)."""
    return f"$(find clearpath_platform_description)/urdf/{macro}/{macro}.urdf.xacro"


def run_entry(e: Entry, src: Path, env: dict[str, str], tmp: Path) -> Row:
    """Expand, import, build and compare one robot."""
    from armcli.compiler.expand import expand_urdfs
    from armcli.compiler.xacro_writer import top_level_files
    from armcli.errors import ArmcliError
    from armcli.importer.run import import_urdf

    row = Row(e.label)
    path = src / e.path
    try:
        xml = _expand(path, e.args, env, tmp)
    except (RuntimeError, subprocess.TimeoutExpired) as exc:
        row.stage, row.error = "expand", str(exc)[:200]
        return row
    out = tmp / "armcli.yaml"
    try:
        result = import_urdf(xml, str(path), out, source_dir=path.parent)
    except ArmcliError as exc:
        row.stage, row.error = "import", str(exc)[:200]
        return row
    row.differences = [str(d) for d in result.differences]
    row.passthrough = len(result.passthrough)
    try:
        built = expand_urdfs(result.spec)
    except ArmcliError as exc:
        row.stage, row.error = "build", str(exc)[:200]
        return row
    spec = result.spec
    main = next(n for n in (f"{spec.name}.urdf", *top_level_files(spec)) if n in built)
    row.stage = "ok"
    row.pinocchio = pinocchio_difference(xml, built[main])
    return row


def entries(corpus: Path) -> list[Entry]:
    """The real-descriptions entries, then every example-robot-data URDF not among them."""
    erd = corpus / "src" / "example-robot-data" / "robots"
    have = {e.path for e in ENTRIES}
    more = []
    for p in sorted(erd.rglob("*.urdf")):
        rel = p.relative_to(corpus / "src").as_posix()
        if rel not in have:
            more.append(Entry("erd " + p.relative_to(erd).as_posix(), rel))
    return [*ENTRIES, *WRAPPED, *more]


def main() -> None:
    """Run every entry and print one line each, then the counts."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("corpus", type=Path)
    ap.add_argument("--only", action="append", default=[])
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH",)}
    env["AMENT_PREFIX_PATH"] = str(a.corpus / "install")
    todo = [e for e in entries(a.corpus) if not a.only or e.label in a.only]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for e in todo:
            row = run_entry(e, a.corpus / "src", env, Path(tmp))
            rows.append(row)
            what = (
                row.error
                if row.stage != "ok"
                else (
                    f"{len(row.differences)} difference(s), pinocchio {row.pinocchio}, "
                    f"{row.passthrough} passthrough"
                )
            )
            print(f"{row.label:40s} {row.stage:7s} {what}", flush=True)
            for d in row.differences[:3]:
                print(f"    {d}", flush=True)
    ok = [r for r in rows if r.stage == "ok"]
    exact = [r for r in ok if not r.differences]
    same = [r for r in ok if r.pinocchio == "same"]
    print(
        f"\n{len(rows)} robots: {len(ok)} import and build, {len(exact)} round-trip exactly "
        f"(import's comparison), {len(same)} give the same Pinocchio model"
    )
    if a.json is not None:
        a.json.write_text(json.dumps([asdict(r) for r in rows], indent=1))


if __name__ == "__main__":
    main()
