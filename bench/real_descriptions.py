"""Every armcli command over real robot descriptions: the table of issue 19.

    python bench/real_descriptions.py [CORPUS] [--json OUT] [--python EXE] [--only TEXT]
    python bench/real_descriptions.py --compare BEFORE.json AFTER.json
    python bench/real_descriptions.py [CORPUS] --sweep

CORPUS (else $ARMCLI_CORPUS, else /work/corpus) holds `src/` (public description
repositories, as cloned) and `install/` (the ament prefix `bench/ament_workspace.py`
makes from them; made in a temporary directory when absent). Without a corpus the
script says so and exits 0. Nothing from the corpus is copied anywhere.

Each entry of ENTRIES (a robot's top-level description file and the xacro arguments
it needs) is run through the real CLI as a user with a sourced ROS 2 workspace runs
it: only AMENT_PREFIX_PATH set (no ROS_PACKAGE_PATH). Per entry:

- expansion: `armcli expand FILE ARGS` (an armcli without `expand`: `armcli tree`),
  also without the arguments, with only ROS_PACKAGE_PATH (the source tree) instead of
  the ament prefix, and with `--trust-xacro` (the sandboxed real xacro);
- tree: `armcli tree FILE ARGS` exits 0;
- the reference: the real xacro, unsandboxed, with an `ament_index_python` stand-in
  (`<prefix>/share/NAME` from the ament index, as ROS 2's) so that `$(find)` works,
  and whether armcli's expansion equals it (the banner comment naming the file aside);
- check: exit code, error findings by rule, and false ones: `mesh-missing` for a mesh
  the ROS 2 resolution finds (package:// through the ament index, file://, relative);
  and the error findings that name an unknown package;
- simulate --urdf along a small move of every joint (gains 100/10), export mjcf (and
  whether MuJoCo then loads the written model), render: exit codes and first lines.

`--sweep`: beyond ENTRIES, every `*.xacro` file under src/ (outside test directories),
without arguments: where the real xacro expands it, does armcli's safe mode give the same
document (library call, this interpreter's armcli)? Macro libraries count too (an empty
robot each): every construct a description uses is exercised somewhere.

`--python EXE` runs the CLI with another interpreter, e.g. a venv whose armcli is an older
checkout, for a "before" run (PYTHONPATH does not override an editable install).
CPU: about 20 s per entry; run it once, niced, for the numbers.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlparse

from lxml import etree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ament_workspace import INDEX, make_prefix

DEFAULT_CORPUS = Path("/work/corpus")
TIMEOUT_S = 300.0
KP, KD = "100", "10"
MOVE_FRACTION = 0.25  # each joint moves a quarter of its range from its midpoint
CONTINUOUS_MOVE = 0.5  # [rad] for joints without limits


@dataclass(frozen=True)
class Entry:
    """One robot: its top-level file under src/ and the xacro arguments it needs."""

    label: str
    path: str
    args: tuple[str, ...] = ()


# The robots of issue 19 (and more): arms, mobile bases, demos. Arguments are what each
# file needs to describe that robot (UR's `name` is read before its declaration).
UR = "Universal_Robots_ROS2_Description/urdf/ur.urdf.xacro"
KORTEX = "ros2_kortex/kortex_description/robots/"
XARM = "xarm_ros2/xarm_description/urdf/xarm_device.urdf.xacro"
MOVEIT = "moveit_resources/"
DEMOS = "ros2_control_demos/"
ERD = "example-robot-data/robots/"
ENTRIES = [
    Entry("UR5e", UR, ("name:=ur5e", "ur_type:=ur5e")),
    Entry("UR10e", UR, ("name:=ur10e", "ur_type:=ur10e")),
    Entry("Franka FR3", "franka_description/robots/fr3/fr3.urdf.xacro"),
    Entry("Franka FER", "franka_description/robots/fer/fer.urdf.xacro"),
    Entry("Franka FP3", "franka_description/robots/fp3/fp3.urdf.xacro"),
    Entry("Kinova Gen3 7-DoF", KORTEX + "kinova.urdf.xacro", ("name:=gen3", "arm:=gen3", "dof:=7")),
    Entry("Kinova Gen3 6-DoF", KORTEX + "kinova.urdf.xacro", ("name:=gen3", "arm:=gen3", "dof:=6")),
    Entry("Kinova Gen3 (gen3.xacro)", KORTEX + "gen3.xacro", ("dof:=7",)),
    Entry("xArm6", XARM, ("dof:=6",)),
    Entry("xArm7", XARM, ("dof:=7",)),
    Entry("Lite6", XARM, ("robot_type:=lite", "dof:=6")),
    Entry("TIAGo", "tiago_robot/tiago_description/robots/tiago.urdf.xacro"),
    Entry("MoveIt panda", MOVEIT + "panda_description/urdf/panda.urdf.xacro"),
    Entry("MoveIt panda config", MOVEIT + "panda_moveit_config/config/panda.urdf.xacro"),
    Entry("MoveIt dual panda", MOVEIT + "dual_arm_panda_moveit_config/config/panda.urdf.xacro"),
    Entry("MoveIt fanuc", MOVEIT + "fanuc_moveit_config/config/fanuc.urdf.xacro"),
    Entry("ABB IRB2400", "abb/abb_irb2400_support/urdf/irb2400.xacro"),
    Entry("ABB IRB4400", "abb/abb_irb4400_support/urdf/irb4400l_30_243.xacro"),
    Entry("ABB IRB6640", "abb/abb_irb6640_support/urdf/irb6640_185_280.xacro"),
    Entry("Fanuc M-10iA", "fanuc/fanuc_m10ia_support/urdf/m10ia.xacro"),
    Entry("Fanuc M-16iB", "fanuc/fanuc_m16ib_support/urdf/m16ib20.xacro"),
    Entry("Motoman GP7", "motoman/motoman_gp7_support/urdf/gp7.xacro"),
    Entry("Motoman SIA20D", "motoman/motoman_sia20d_support/urdf/sia20d.xacro"),
    Entry("Husky", "husky/husky_description/urdf/husky.urdf.xacro"),
    Entry("Jackal", "jackal/jackal_description/urdf/jackal.urdf.xacro"),
    Entry("rrbot (demo 1)", DEMOS + "example_1/description/urdf/rrbot.urdf.xacro"),
    Entry("r6bot (demo 7)", DEMOS + "example_7/description/urdf/r6bot.urdf.xacro"),
    Entry("diffbot (demo 2)", DEMOS + "example_2/description/urdf/diffbot.urdf.xacro"),
    Entry("Kinova Gen3 lite URDF", KORTEX + "gen3_lite.urdf"),
    Entry("Kinova Gen3 2F-85 URDF", KORTEX + "gen3_2f85.urdf"),
    Entry("ABB IRB2400 URDF", "abb/abb_irb2400_support/urdf/irb2400.urdf"),
    Entry("MoveIt fanuc URDF", MOVEIT + "fanuc_description/urdf/fanuc.urdf"),
    Entry("erd UR5", ERD + "ur_description/urdf/ur5_robot.urdf"),
    Entry("erd panda", ERD + "panda_description/urdf/panda.urdf"),
    Entry("erd double pendulum", ERD + "double_pendulum_description/urdf/double_pendulum.urdf"),
    Entry("erd TALOS left arm", ERD + "talos_data/robots/talos_left_arm.urdf"),
    Entry("erd Z1", ERD + "z1_description/urdf/z1.urdf"),
]

SHIM = '''"""ament_index_python for the bench's reference: <prefix>/share/NAME from the index."""
import os
class PackageNotFoundError(KeyError):
    pass
def get_package_prefix(name):
    for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        marker = os.path.join(prefix, "share", "ament_index", "resource_index", "packages", name)
        if prefix and os.path.isfile(marker):
            return prefix
    raise PackageNotFoundError(f"package {name!r} not found")
def get_package_share_directory(name, print_warning=True):
    return os.path.join(get_package_prefix(name), "share", name)
'''
REFERENCE = """
import sys, xacro
args = dict(a.split(":=", 1) for a in sys.argv[2:])
try:
    doc = xacro.process_file(sys.argv[1], mappings=args)
except BaseException as exc:
    inner = exc
    while getattr(inner, "exc", None) is not None:
        inner = inner.exc
    sys.stderr.write(f"{type(inner).__name__}: {' '.join(str(inner).split())[:200]}\\n")
    sys.exit(1)
sys.stdout.buffer.write(doc.toprettyxml(indent="  ", encoding="utf-8"))
"""
SWEEP = """
import contextlib, io, sys
from pathlib import Path
import xacro
from armcli.urdf.source import allowed_roots
from armcli.xacro.args import XacroInputs
from armcli.xacro.safe import expand_safe_report
def strip(xml):
    return b"\\n".join(ln for ln in xml.splitlines() if b"autogenerated by xacro" not in ln)
src = Path(sys.argv[1])
files = sorted(p for p in src.rglob("*.xacro") if "test" not in p.parts)
n = {"files": len(files), "real xacro expands": 0, "armcli equal": 0}
problems = []
for path in files:
    try:
        with contextlib.redirect_stderr(io.StringIO()):
            ref = xacro.process_file(str(path)).toprettyxml(indent="  ", encoding="utf-8")
    except BaseException:
        continue
    n["real xacro expands"] += 1
    try:
        with contextlib.redirect_stderr(io.StringIO()):
            out, _ = expand_safe_report(path, allowed_roots(path.parent), XacroInputs())
    except Exception as exc:
        problems.append(f"{path.relative_to(src)}: {' '.join(str(exc).split())[:200]}")
        continue
    if strip(out) == strip(ref):
        n["armcli equal"] += 1
    else:
        problems.append(f"{path.relative_to(src)}: differs from real xacro")
for key, value in n.items():
    print(f"{key}: {value}")
for line in problems:
    print("  " + line)
"""


@dataclass
class Row:
    """What happened to one entry."""

    label: str
    xacro: bool
    reference: str = ""  # "ok" or the reference's error
    expanded: bool = False
    expand_error: str = ""
    expanded_no_args: bool | None = None  # None: the entry takes no arguments
    expanded_ros: bool | None = None  # ROS_PACKAGE_PATH only; None: not run
    trusted: str = ""  # --trust-xacro: "equal", "differs" or its error
    tree: str = ""
    unknown_package: int = 0
    continuous: int = 0  # continuous joints of the model
    equal: bool | None = None  # None: no reference or no expansion to compare
    check_exit: int | None = None
    errors: dict[str, int] = field(default_factory=dict)
    false_errors: int = 0
    material_conflicts: int = 0
    simulate: str = ""
    export: str = ""
    render: str = ""
    seconds: float = 0.0


class Runner:
    """Runs the CLI and the reference with the workspace's environment."""

    def __init__(self, corpus: Path, prefix: Path, tmp: Path, python: str) -> None:
        self.src, self.prefix, self.tmp = corpus / "src", prefix, tmp
        (tmp / "shim" / "ament_index_python").mkdir(parents=True)
        (tmp / "shim" / "ament_index_python" / "__init__.py").write_text("")
        (tmp / "shim" / "ament_index_python" / "packages.py").write_text(SHIM)
        env = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH", "PYTHONPATH")}
        self.env = {**env, "AMENT_PREFIX_PATH": str(prefix), "COLUMNS": "200"}
        no_ament = {k: v for k, v in self.env.items() if k != "AMENT_PREFIX_PATH"}
        self.ros_env = {**no_ament, "ROS_PACKAGE_PATH": str(self.src)}
        self.python = python
        self.has_expand = self.cli("expand", "--help").returncode == 0

    def cli(
        self, *args: str, env: dict[str, str] | None = None
    ) -> subprocess.CompletedProcess[bytes]:
        return self._run([self.python, "-m", "armcli.cli", *args], env or self.env)

    def reference(self, path: Path, args: tuple[str, ...]) -> subprocess.CompletedProcess[bytes]:
        env = {**self.env, "PYTHONPATH": str(self.tmp / "shim")}
        return self._run([sys.executable, "-c", REFERENCE, str(path), *args], env)

    def sweep(self) -> str:
        """SWEEP over src/ (one process: real xacro and the safe mode, file by file)."""
        env = {**self.env, "PYTHONPATH": str(self.tmp / "shim")}
        argv = [sys.executable, "-c", SWEEP, str(self.src)]
        proc = subprocess.run(argv, capture_output=True, env=env, cwd=self.tmp, check=False)
        return proc.stdout.decode() + proc.stderr.decode()[-2000:]

    def _run(self, argv: list[str], env: dict[str, str]) -> subprocess.CompletedProcess[bytes]:
        try:
            return subprocess.run(
                argv, capture_output=True, env=env, timeout=TIMEOUT_S, cwd=self.tmp, check=False
            )
        except subprocess.TimeoutExpired:
            return subprocess.CompletedProcess(argv, -1, b"", f"timeout {TIMEOUT_S:g} s".encode())


def _first_error(proc: subprocess.CompletedProcess[bytes]) -> str:
    lines = [ln for ln in proc.stderr.decode("utf-8", "replace").splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error:")]  # an informational line first
    errors = errors or [ln for ln in lines if not ln.startswith(("note:", "warning:"))]
    return (errors or lines or [f"exit {proc.returncode}"])[0][:300]


def _without_banner(xml: bytes) -> bytes:
    return b"\n".join(ln for ln in xml.splitlines() if b"autogenerated by xacro from" not in ln)


def ros_resolves(uri: str, base: Path, prefix: Path) -> bool:
    """Whether ROS 2 finds the mesh: package:// through the ament index, file://, relative."""
    parsed = urlparse(uri)
    if parsed.scheme == "package":
        name, rel = parsed.netloc, unquote(parsed.path).lstrip("/")
        return (prefix / INDEX / name).is_file() and (prefix / "share" / name / rel).is_file()
    if parsed.scheme == "file":
        return Path(unquote(parsed.path)).is_file()
    return not parsed.scheme and (base / uri).is_file()


def continuous_joints(xml: bytes) -> int:
    """How many continuous joints (unbounded angle) the model has."""
    root = etree.fromstring(xml, etree.XMLParser(resolve_entities=False))
    return sum(j.get("type") == "continuous" for j in root.findall("joint"))


UNKNOWN_PACKAGE = ("unknown package", "no package")


def movable_joints(xml: bytes) -> list[tuple[str, float]]:
    """(joint, target) for every moving non-mimic joint: a quarter range from the middle."""
    root = etree.fromstring(xml, etree.XMLParser(resolve_entities=False))
    out = []
    for j in root.findall("joint"):
        kind = j.get("type")
        if kind not in ("revolute", "prismatic", "continuous") or j.find("mimic") is not None:
            continue
        lim = j.find("limit")
        lo, hi = (lim.get("lower"), lim.get("upper")) if lim is not None else (None, None)
        if kind == "continuous" or lo is None or hi is None:
            out.append((str(j.get("name")), CONTINUOUS_MOVE))
            continue
        mid, span = (float(lo) + float(hi)) / 2, float(hi) - float(lo)
        out.append((str(j.get("name")), mid + MOVE_FRACTION * span))
    return out


def run_entry(r: Runner, e: Entry) -> Row:
    """Every command on one entry."""
    start = time.monotonic()
    path = r.src / e.path
    row = Row(e.label, xacro=path.suffix == ".xacro")
    ref = r.reference(path, e.args) if row.xacro else None
    ref_xml = ref.stdout if ref is not None and ref.returncode == 0 else None
    row.reference = "ok" if ref is None or ref_xml is not None else _first_error(ref)
    xml = _expansion(r, e, path, row)
    if ref_xml is not None and xml is not None:
        row.equal = _without_banner(xml) == _without_banner(ref_xml)
    if row.xacro:
        _other_expansions(r, e, path, row, ref_xml)
    proc = r.cli("tree", str(path), *e.args)
    row.tree = "ok" if proc.returncode == 0 else f"exit {proc.returncode}: {_first_error(proc)}"
    _check(r, e, path, row)
    model = xml if xml is not None else (ref_xml if row.xacro else path.read_bytes())
    row.continuous = continuous_joints(model) if model else 0
    _simulate(r, e, path, row, model)
    _export(r, e, path, row)
    out = r.tmp / "render.png"
    proc = r.cli("render", str(path), *e.args, "--size", "400x200", "-o", str(out))
    warned = proc.stderr.decode("utf-8", "replace").count("not drawn")
    row.render = f"ok, {warned} mesh warning(s)" if proc.returncode == 0 else _first_error(proc)
    row.seconds = time.monotonic() - start
    return row


def _expansion(r: Runner, e: Entry, path: Path, row: Row) -> bytes | None:
    if not row.xacro:
        return None
    if r.has_expand:
        proc = r.cli("expand", str(path), *e.args)
    else:  # an armcli before `expand`: does any command get the file in?
        proc = r.cli("tree", str(path), *e.args)
    row.expanded = proc.returncode == 0
    row.expand_error = "" if row.expanded else _first_error(proc)
    return proc.stdout if row.expanded and r.has_expand else None


def _other_expansions(r: Runner, e: Entry, path: Path, row: Row, ref_xml: bytes | None) -> None:
    """Without the arguments, with ROS_PACKAGE_PATH only, and with --trust-xacro."""
    command = "expand" if r.has_expand else "tree"
    if e.args:
        row.expanded_no_args = r.cli(command, str(path)).returncode == 0
    row.expanded_ros = r.cli(command, str(path), *e.args, env=r.ros_env).returncode == 0
    if not r.has_expand:  # an older CLI: only `tree` reads the file, and without arguments
        proc = r.cli("tree", "--trust-xacro", str(path))
        row.trusted = "expanded" if proc.returncode == 0 else _first_error(proc)
        return
    proc = r.cli("expand", "--trust-xacro", str(path), *e.args)
    if proc.returncode != 0:
        row.trusted = _first_error(proc)
    elif ref_xml is None:
        row.trusted = "expanded"
    else:
        same = _without_banner(proc.stdout) == _without_banner(ref_xml)
        row.trusted = "equal" if same else "differs"


def _check(r: Runner, e: Entry, path: Path, row: Row) -> None:
    proc = r.cli("check", str(path), *e.args, "--format", "json")
    row.check_exit = proc.returncode
    try:
        doc = json.loads(proc.stdout)
    except ValueError:
        return
    findings = [f for file in doc.get("files", []) for f in file.get("findings", [])]
    errors = [f for f in findings if f.get("severity") == "error"]
    row.errors = dict(Counter(f["rule"] for f in errors))
    row.unknown_package = sum(
        any(text in f.get("message", "") for text in UNKNOWN_PACKAGE) for f in errors
    )
    row.material_conflicts = sum(f["rule"] == "material-conflict" for f in findings)
    for f in errors:
        uri = (f.get("values") or {}).get("uri")
        if f["rule"] == "mesh-missing" and uri and ros_resolves(uri, path.parent, r.prefix):
            row.false_errors += 1


def _simulate(r: Runner, e: Entry, path: Path, row: Row, model: bytes | None) -> None:
    joints = movable_joints(model) if model else []
    if not joints:
        row.simulate = "no expansion" if model is None else "no movable joint"
        return
    names = [n for n, _ in joints]
    message = json.dumps(
        {
            "joint_names": names,
            "points": [{"positions": [t for _, t in joints], "time_from_start": {"sec": 1}}],
        }
    )
    proc = r.cli(
        "simulate", "--urdf", str(path), *e.args, "-m", message, "--kp", KP, "--kd", KD,
        "--duration", "1.5", "--joints", ",".join(names),
    )  # fmt: skip
    row.simulate = (
        "ran" if proc.returncode == 0 else f"exit {proc.returncode}: {_first_error(proc)}"
    )


def _export(r: Runner, e: Entry, path: Path, row: Row) -> None:
    out = r.tmp / "mjcf" / "robot.xml"
    out.parent.mkdir(exist_ok=True)  # export writes into an existing directory
    proc = r.cli("export", "mjcf", str(path), *e.args, "-o", str(out))
    if proc.returncode != 0:
        row.export = f"exit {proc.returncode}: {_first_error(proc)}"
        return
    try:
        import mujoco

        mujoco.MjModel.from_xml_path(str(out))
        row.export = "loads in MuJoCo"
    except ImportError:
        row.export = "exit 0 (mujoco not installed)"
    except Exception as exc:  # MuJoCo refuses what armcli wrote
        row.export = f"exit 0 but MuJoCo refuses: {' '.join(str(exc).split())[:200]}"


def summary(rows: list[Row]) -> dict[str, Any]:
    """The issue's table as numbers."""
    xacro = [r for r in rows if r.xacro]
    referenced = [r for r in xacro if r.reference == "ok"]
    return {
        "entries": len(rows),
        "xacro entries": len(xacro),
        "expanded (xacro)": sum(r.expanded for r in xacro),
        "expanded without the arguments (xacro)": sum(
            r.expanded if r.expanded_no_args is None else r.expanded_no_args for r in xacro
        ),
        "expanded with ROS_PACKAGE_PATH only (xacro)": sum(bool(r.expanded_ros) for r in xacro),
        "--trust-xacro expands (xacro)": sum(
            r.trusted in ("equal", "differs", "expanded") for r in xacro
        ),
        "--trust-xacro equal to real xacro": sum(r.trusted == "equal" for r in xacro),
        "real xacro expands (xacro)": len(referenced),
        "expanded where real xacro does": sum(r.expanded for r in referenced),
        "equal to real xacro": sum(r.equal is True for r in referenced),
        "tree exit 0": sum(r.tree == "ok" for r in rows),
        "check usable (exit 0/1)": sum(r.check_exit in (0, 1) for r in rows),
        "files with unknown-package errors": sum(
            r.unknown_package > 0 or any(t in r.expand_error for t in UNKNOWN_PACKAGE) for r in rows
        ),
        "unknown-package error findings": sum(r.unknown_package for r in rows),
        "false error findings": sum(r.false_errors for r in rows),
        "error findings": sum(sum(r.errors.values()) for r in rows),
        "material-conflict warnings": sum(r.material_conflicts for r in rows),
        "simulate ran": sum(r.simulate == "ran" for r in rows),
        "models with continuous joints": sum(r.continuous > 0 for r in rows),
        "simulate ran, continuous joints": sum(
            r.simulate == "ran" and r.continuous > 0 for r in rows
        ),
        "simulate refuses continuous joints": sum("RUBY" in r.simulate for r in rows),
        "export loads in MuJoCo": sum(r.export == "loads in MuJoCo" for r in rows),
        "export exit 0, MuJoCo refuses": sum("MuJoCo refuses" in r.export for r in rows),
        "export exit != 0": sum(
            r.export.startswith("exit ") and not r.export.startswith("exit 0") for r in rows
        ),
        "render exit 0": sum(r.render.startswith("ok") for r in rows),
    }


def print_rows(rows: list[Row]) -> None:
    """One line per entry, then the details of what failed."""
    print(
        "| robot | expand | = xacro | trusted | tree | check | false err | simulate | export "
        "| render |"
    )
    print("|---|---|---|---|---|---|---:|---|---|---|")
    for r in rows:
        exp = "-" if not r.xacro else ("ok" if r.expanded else "FAIL")
        eq = {True: "yes", False: "NO", None: "-"}[r.equal]
        sim = "ran" if r.simulate == "ran" else r.simulate.split(":")[0]
        exp_ = r.export if r.export == "loads in MuJoCo" else r.export.split(":")[0]
        ren = r.render if r.render.startswith("ok") else "FAIL"
        trusted = "-" if not r.xacro else r.trusted if r.trusted in ("equal", "differs") else "FAIL"
        tree = "ok" if r.tree == "ok" else "FAIL"
        print(
            f"| {r.label} | {exp} | {eq} | {trusted} | {tree} | exit {r.check_exit} | "
            f"{r.false_errors} | {sim} | {exp_} | {ren} |"
        )
    print()
    for r in rows:
        notes = [
            f"reference: {r.reference}" if r.reference != "ok" else "",
            f"expand: {r.expand_error}" if r.expand_error else "",
            f"--trust-xacro: {r.trusted}"
            if r.xacro and r.trusted not in ("equal", "expanded")
            else "",
            f"tree: {r.tree}" if r.tree != "ok" else "",
            f"check errors: {r.errors}" if r.errors else "",
            f"simulate: {r.simulate}" if r.simulate != "ran" else "",
            f"export: {r.export}" if r.export != "loads in MuJoCo" else "",
            f"render: {r.render}" if not r.render.startswith("ok") else "",
        ]
        shown = [n for n in notes if n]
        if shown:
            print(f"- {r.label}: " + "; ".join(shown))


def compare(before: dict[str, Any], after: dict[str, Any]) -> str:
    """The summaries of two runs side by side, over the current entries both ran."""
    common = {r["label"] for r in before["rows"]} & {r["label"] for r in after["rows"]}
    common &= {e.label for e in ENTRIES}
    sums = [
        summary([Row(**r) for r in run["rows"] if r["label"] in common]) for run in (before, after)
    ]
    lines = ["| | before | after |", "|---|---:|---:|"]
    lines += [f"| {key} | {sums[0][key]} | {sums[1][key]} |" for key in sums[1]]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line (see the module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("corpus", nargs="?", type=Path)
    ap.add_argument("--json", type=Path, help="also write the rows and summary as JSON")
    ap.add_argument("--python", default=sys.executable, help="interpreter running the CLI")
    ap.add_argument("--only", help="only entries whose label contains this text")
    ap.add_argument("--compare", nargs=2, type=Path, metavar=("BEFORE", "AFTER"))
    ap.add_argument("--sweep", action="store_true", help="every *.xacro file, no arguments")
    args = ap.parse_args(argv)
    if args.compare:
        before, after = (json.loads(p.read_text()) for p in args.compare)
        sys.stdout.write(compare(before, after))
        return 0
    corpus = args.corpus or Path(os.environ.get("ARMCLI_CORPUS", DEFAULT_CORPUS))
    if not (corpus / "src").is_dir():
        print(f"no corpus at {corpus} (expected {corpus / 'src'}): skipped")
        return 0
    with tempfile.TemporaryDirectory(prefix="armcli-bench-") as tmp:
        prefix = corpus / "install"
        if not (prefix / INDEX).is_dir():
            prefix = Path(tmp) / "install"
            make_prefix(corpus / "src", prefix)
        runner = Runner(corpus, prefix, Path(tmp), args.python)
        if args.sweep:
            sys.stdout.write(runner.sweep())
            return 0
        entries = [e for e in ENTRIES if not args.only or args.only in e.label]
        rows = []
        for e in entries:
            rows.append(run_entry(runner, e))
            print(f"{e.label}: {rows[-1].seconds:.0f} s", file=sys.stderr)
    print_rows(rows)
    result = {"summary": summary(rows), "rows": [asdict(r) for r in rows]}
    print()
    for key, value in result["summary"].items():
        print(f"{key}: {value}")
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
