"""Expand a xacro file in a resource-limited child process: safe mode and --trust-xacro.

Two kinds of expansion run here, both in a child with a wall-clock timeout,
CPU, memory, file-size and open-file limits, an empty environment, no stdin,
its own process group (killed as a whole) and stdout read with a streaming
cap (the child is killed as soon as it writes more than the cap):

- `expand_foreign` (the default): xacro.safe's expansion, where the file
  cannot run code (AST-whitelisted expressions, confined includes);
- `expand_untrusted` (`--trust-xacro`): xacro itself, which runs Python from
  the file. It runs under xacro.jail (bubblewrap: read-only root, private
  /tmp, no network, PID namespace, cleared environment) when available, and
  only with `--trust-xacro=unsandboxed` otherwise. See docs/security.md.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import os
import selectors
import signal
import site
import subprocess
import sys
import sysconfig
import time
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from armcli.errors import InputError, XacroRefusedError
from armcli.io.userfile import check_regular
from armcli.xacro.args import XacroInputs
from armcli.xacro.jail import jail_argv, sandbox_problem, seccomp_program
from armcli.xacro.safe import request_json

XACRO_TIMEOUT = 20.0  # wall clock [s]
XACRO_CPU_SECONDS = 20
XACRO_MEMORY_BYTES = 1 << 30
XACRO_MAX_OUTPUT = 10_000_000  # same cap as urdf.read.MAX_URDF_BYTES
XACRO_MAX_STDERR = 4_000_000  # the report carries the source map: ~15 bytes per element
XACRO_MAX_FILES = 64
_CHUNK = 65536

_SCRIPT = """
import json, sys, types

# $(find NAME) asks ament_index_python (ROS 2, not on PyPI): armcli's own lookup answers,
# from the package map in argv[2] (armcli.io.packages, resolved before the jail).
_packages = json.loads(sys.argv[2])
class PackageNotFoundError(KeyError):
    pass
def get_package_share_directory(name, print_warning=True):
    if name not in _packages:
        raise PackageNotFoundError(
            f"package {name!r} not found by armcli (--package-dir, AMENT_PREFIX_PATH, "
            "ROS_PACKAGE_PATH, the packages enclosing the file)")
    return _packages[name]
_index = types.ModuleType("ament_index_python")
_index.packages = types.ModuleType("ament_index_python.packages")
_index.packages.get_package_share_directory = get_package_share_directory
_index.packages.PackageNotFoundError = PackageNotFoundError
sys.modules["ament_index_python"] = _index
sys.modules["ament_index_python.packages"] = _index.packages

class _Args(dict):
    seen = set()
    def __contains__(self, key):
        self.seen.add(key)
        return dict.__contains__(self, key)
    def __getitem__(self, key):
        self.seen.add(key)
        return dict.__getitem__(self, key)

import xacro
try:
    given = dict(a.split(":=", 1) for a in sys.argv[3:])
    args = _Args(given)
    doc = xacro.process_file(sys.argv[1], mappings=args)
except BaseException as exc:
    inner = exc
    while getattr(inner, "exc", None) is not None:
        inner = inner.exc
    text = f"{type(inner).__name__}: {' '.join(str(inner).split())}"
    if inner is not exc:
        text += " (" + str(exc).strip().splitlines()[-1] + ")"
    sys.stderr.write(text.strip()[:400] + "\\n")
    sys.exit(1)
sys.stdout.buffer.write(doc.toprettyxml(indent="  ", encoding="utf-8"))
unused = [n for n in given if n not in args.seen]
used = {"args": dict(args), "given": list(given), "unused": unused}
sys.stderr.write("\\n" + json.dumps({"kind": "ok", "expansion": used}) + "\\n")
"""
_SAFE_SCRIPT = """
import sys
if sys.argv[1]:
    sys.path.insert(0, sys.argv[1])
from armcli.xacro.safe import child_main
sys.exit(child_main(sys.argv[2:]))
"""


def limit_child() -> None:
    """Resource limits, applied in the child between fork and exec."""
    import resource

    resource.setrlimit(resource.RLIMIT_CPU, (XACRO_CPU_SECONDS, XACRO_CPU_SECONDS))
    resource.setrlimit(resource.RLIMIT_AS, (XACRO_MEMORY_BYTES, XACRO_MEMORY_BYTES))
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))  # may not write files
    resource.setrlimit(resource.RLIMIT_NOFILE, (XACRO_MAX_FILES, XACRO_MAX_FILES))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


class ChildResult:
    """Exit status and captured (capped) output of a limited child."""

    def __init__(self, returncode: int, out: bytes, err: bytes, why: str | None) -> None:
        self.returncode = returncode
        self.out = out
        self.err = err
        self.why = why  # set when armcli killed the child (timeout, output cap)


def run_limited(
    argv: Sequence[str],
    cwd: Path,
    *,
    timeout: float = XACRO_TIMEOUT,
    env: dict[str, str] | None = None,
    pass_fds: Sequence[int] = (),
) -> ChildResult:
    """Run `argv` limited, reading stdout/stderr with streaming caps; kill the group on excess."""
    proc = subprocess.Popen(
        list(argv),
        cwd=cwd,
        env=env if env is not None else {"PATH": os.defpath, "LANG": "C.UTF-8"},
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        preexec_fn=limit_child,  # no threads exist before exec
        pass_fds=tuple(pass_fds),
        start_new_session=True,
    )
    assert proc.stdout is not None and proc.stderr is not None
    caps: dict[object, int] = {proc.stdout: XACRO_MAX_OUTPUT, proc.stderr: XACRO_MAX_STDERR}
    bufs: dict[object, bytearray] = {proc.stdout: bytearray(), proc.stderr: bytearray()}
    deadline = time.monotonic() + timeout
    why = _pump(proc, caps, bufs, deadline, timeout)
    if why is None:  # both streams closed: the child may still run (closed them and slept)
        try:
            proc.wait(timeout=max(deadline - time.monotonic(), 0.0))
        except subprocess.TimeoutExpired:
            why = f"took longer than {timeout:g} s"
    if why is not None:
        _kill_group(proc.pid)
    proc.wait()
    proc.stdout.close()
    proc.stderr.close()
    return ChildResult(proc.returncode, bytes(bufs[proc.stdout]), bytes(bufs[proc.stderr]), why)


def _pump(
    proc: subprocess.Popen[bytes],
    caps: dict[object, int],
    bufs: dict[object, bytearray],
    deadline: float,
    timeout: float,
) -> str | None:
    with selectors.DefaultSelector() as sel:
        for stream in caps:
            sel.register(stream, selectors.EVENT_READ)  # type: ignore[arg-type]
        while sel.get_map():
            left = deadline - time.monotonic()
            if left <= 0:
                return f"took longer than {timeout:g} s"
            for key, _ in sel.select(timeout=left):
                chunk = os.read(key.fd, _CHUNK)
                if not chunk:
                    sel.unregister(key.fileobj)
                    continue
                buf = bufs[key.fileobj]
                buf += chunk
                if len(buf) > caps[key.fileobj]:
                    what = "output" if key.fileobj is proc.stdout else "error output"
                    return f"{what} is larger than {caps[key.fileobj]} bytes"
    return None


def _kill_group(pgid: int) -> None:
    with contextlib.suppress(ProcessLookupError):
        os.killpg(pgid, signal.SIGKILL)


def _python() -> list[str]:
    return [sys.executable, "-I"]


def _armcli_root() -> str:
    """The directory this armcli is imported from, when `-I` would not find it by itself.

    An isolated child sees site-packages but no PYTHONPATH: from a source checkout (a
    worktree, PYTHONPATH=src) it would import whichever armcli is installed, a different
    version of the safe expander than the parent's. Empty for an installed armcli.
    """
    import armcli

    root = os.path.dirname(os.path.dirname(os.path.abspath(armcli.__file__)))
    return "" if os.path.basename(root) in ("site-packages", "dist-packages") else root


def expand_foreign(path: str | Path, roots: Sequence[Path], request: str | None = None) -> bytes:
    """Safe-mode expansion (xacro.safe) of a foreign xacro file in a limited child."""
    return run_safe(path, request or request_json(roots, XacroInputs()))[0]


def run_safe(path: str | Path, request: str) -> tuple[bytes, dict[str, Any]]:
    """xacro.safe's child on `path` with its JSON `request`: the URDF bytes and its report."""
    p = Path(path)
    check_regular(p, "xacro file")
    argv = [*_python(), "-c", _SAFE_SCRIPT, _armcli_root(), os.path.abspath(p), request]
    res = run_limited(argv, p.resolve().parent, env={"PATH": os.defpath, "LANG": "C.UTF-8"})
    if res.why is not None:
        raise InputError(f"xacro expansion {res.why}", file=p)
    if res.returncode != 0:
        _raise_report(p, res)
    return res.out, _report(res) or {}


def _report(res: ChildResult) -> dict[str, Any] | None:
    """The JSON object on the child's last stderr line (None when there is none)."""
    lines = [ln for ln in res.err.decode("utf-8", "replace").splitlines() if ln.strip()]
    try:
        rep = json.loads(lines[-1]) if lines else None
    except ValueError:
        return None
    return rep if isinstance(rep, dict) else None


def _raise_report(p: Path, res: ChildResult) -> None:
    rep = _report(res)
    if rep is not None and "message" in rep:
        cls = XacroRefusedError if rep.get("kind") == "refused" else InputError
        file = rep.get("file") or os.path.abspath(p)
        same = file in (str(p.resolve()), os.path.abspath(p))
        shown = p if same else file  # the path as the user gave it
        raise cls(str(rep["message"]), file=shown, line=rep.get("line"))
    why = _last_line(res) or f"exit status {res.returncode}"
    raise InputError(f"xacro expansion failed: {why}", file=p)


def _last_line(res: ChildResult) -> str | None:
    if res.returncode < 0:
        return f"killed by signal {signal.Signals(-res.returncode).name}"
    lines = [ln for ln in res.err.decode("utf-8", "replace").splitlines() if ln.strip()]
    return lines[-1] if lines else None


def expand_untrusted(
    path: str | Path,
    *,
    mappings: dict[str, str] | None = None,
    timeout: float = XACRO_TIMEOUT,
    unsandboxed: bool = False,
    roots: Sequence[Path] = (),
) -> bytes:
    """The expanded URDF bytes of a user-trusted xacro file; InputError if expansion fails.

    xacro runs inside xacro.jail's bubblewrap sandbox, where it can read only the
    system and interpreter directories, the file's directory, ROS_PACKAGE_PATH and
    `roots` (package roots); where the sandbox cannot run, the expansion is refused
    unless `unsandboxed` (`--trust-xacro=unsandboxed`: the resource limits only).
    """
    opts = {"mappings": mappings, "timeout": timeout, "unsandboxed": unsandboxed}
    return run_trusted(path, roots=roots, **opts)[0]  # type: ignore[arg-type]


def run_trusted(
    path: str | Path,
    *,
    mappings: Mapping[str, str] | None = None,
    packages: Mapping[str, Path] | None = None,
    environ: Mapping[str, str] | None = None,
    timeout: float = XACRO_TIMEOUT,
    unsandboxed: bool = False,
    roots: Sequence[Path] = (),
) -> tuple[bytes, dict[str, Any]]:
    """The trusted file through xacro itself (see expand_untrusted): URDF and report.

    `packages` answers `$(find NAME)` (an ament_index_python stand-in in the child);
    `environ` are the user's --env values, the only variables besides PATH and LANG.
    """
    p = Path(path)
    check_regular(p, "xacro file")
    args = [f"{k}:={v}" for k, v in (mappings or {}).items()]
    env = {**(environ or {}), "PATH": os.defpath, "LANG": "C.UTF-8"}
    if "ROS_PACKAGE_PATH" in os.environ:
        env["ROS_PACKAGE_PATH"] = os.environ["ROS_PACKAGE_PATH"]
    found = json.dumps({k: str(v) for k, v in (packages or {}).items()})
    argv = [*_python(), "-c", _SCRIPT, os.path.abspath(p), found, *args]
    if unsandboxed:
        res = run_limited(argv, p.resolve().parent, timeout=timeout, env=env)
    else:
        res = _run_jailed(argv, p, env, timeout, jail_readable(p, env, roots))
    if res.why is not None:
        raise InputError(f"xacro expansion {res.why}", file=p)
    if res.returncode != 0:
        why = _last_line(res) or f"exit status {res.returncode}, no message"
        raise InputError(f"xacro expansion failed: {why}", file=p)
    return res.out, _report(res) or {}


def _interpreter_dirs() -> list[Path]:
    """Where this Python, its standard library, site-packages and xacro live.

    Nothing else of sys.path: it may hold the working directory, a home directory perhaps.
    """
    dirs = {sys.prefix, sys.base_prefix, sys.exec_prefix, os.path.dirname(sys.executable)}
    dirs.add(os.path.dirname(os.path.realpath(sys.executable)))
    dirs |= {v for k, v in sysconfig.get_paths().items() if k.endswith(("stdlib", "lib"))}
    dirs |= set(site.getsitepackages())
    for name in ("xacro", "yaml"):  # what _SCRIPT imports, wherever it is installed
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.origin:
            dirs.add(str(Path(spec.origin).parent.parent))
    return [Path(d) for d in sorted(dirs) if os.path.isdir(d)]


def jail_readable(p: Path, env: Mapping[str, str], roots: Iterable[Path] = ()) -> list[Path]:
    """What the sandboxed xacro may read besides the system directories.

    Its own directory, ROS_PACKAGE_PATH entries, `roots` (package roots) and this
    interpreter's directories; xacro.jail binds each read-only at its real path.
    """
    package_path = [Path(r) for r in env.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if r]
    return [p.resolve().parent, *package_path, *roots, *_interpreter_dirs()]


def _run_jailed(
    argv: list[str], p: Path, env: dict[str, str], timeout: float, readable: list[Path]
) -> ChildResult:
    problem = sandbox_problem()
    program = seccomp_program()
    if problem is not None or program is None:
        raise XacroRefusedError(
            f"--trust-xacro runs xacro in a bubblewrap sandbox, which cannot run here: {problem}; "
            "install the Debian package bubblewrap, or pass --trust-xacro=unsandboxed to run "
            "xacro with resource limits only (the file's code can then read your files)",
            file=p,
        )
    read_end, write_end = os.pipe()
    try:
        os.write(write_end, program)
        os.close(write_end)
        cwd = p.resolve().parent
        jailed = jail_argv(argv, readable=readable, env=env, cwd=cwd, seccomp_fd=read_end)
        return run_limited(
            jailed, p.resolve().parent, timeout=timeout, env=env, pass_fds=[read_end]
        )
    finally:
        os.close(read_end)
