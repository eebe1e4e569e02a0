"""Expand a xacro file that armcli did not generate, in a resource-limited subprocess.

Xacro evaluates Python from the file (`${...}`, `$(eval ...)` with builtins),
so a foreign `.xacro` is code. armcli only expands one when the user passes
`--trust-xacro`, and even then in a child process with a wall-clock timeout,
CPU, memory, file-size and open-file limits, an empty environment, no stdin
and its own process group (killed as a whole on timeout). This limits damage
from accidents (runaway recursion, huge output); it is not a security boundary
against a malicious file, which is why the user's explicit trust is required.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

from armcli.errors import InputError
from armcli.userfile import check_regular

XACRO_TIMEOUT = 20.0  # wall clock [s]
XACRO_CPU_SECONDS = 20
XACRO_MEMORY_BYTES = 1 << 30
XACRO_MAX_OUTPUT = 10_000_000  # same cap as urdfxml.MAX_URDF_BYTES
XACRO_MAX_FILES = 64

_SCRIPT = """
import sys, xacro
try:
    args = dict(a.split(":=", 1) for a in sys.argv[2:])
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
"""


def _limit_child() -> None:  # runs in the child between fork and exec
    import resource

    resource.setrlimit(resource.RLIMIT_CPU, (XACRO_CPU_SECONDS, XACRO_CPU_SECONDS))
    resource.setrlimit(resource.RLIMIT_AS, (XACRO_MEMORY_BYTES, XACRO_MEMORY_BYTES))
    resource.setrlimit(resource.RLIMIT_FSIZE, (0, 0))  # may not write files
    resource.setrlimit(resource.RLIMIT_NOFILE, (XACRO_MAX_FILES, XACRO_MAX_FILES))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def expand_untrusted(
    path: str | Path,
    *,
    mappings: dict[str, str] | None = None,
    timeout: float = XACRO_TIMEOUT,
) -> bytes:
    """The expanded URDF bytes of a user-trusted xacro file; InputError if expansion fails."""
    p = Path(path)
    check_regular(p, "xacro file")
    args = [f"{k}:={v}" for k, v in (mappings or {}).items()]
    env = {"PATH": os.defpath, "LANG": "C.UTF-8"}
    if "ROS_PACKAGE_PATH" in os.environ:  # $(find pkg) lookups, the ROS convention
        env["ROS_PACKAGE_PATH"] = os.environ["ROS_PACKAGE_PATH"]
    proc = subprocess.Popen(
        [sys.executable, "-I", "-c", _SCRIPT, str(p.resolve()), *args],
        cwd=p.resolve().parent,
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        preexec_fn=_limit_child,  # no threads exist before exec in the child
        start_new_session=True,
    )
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        raise InputError(f"xacro expansion took longer than {timeout:g} s", file=p) from None
    if proc.returncode != 0:
        lines = [ln for ln in err.decode("utf-8", "replace").splitlines() if ln.strip()]
        why = lines[-1] if lines else f"exit status {proc.returncode}"
        raise InputError(f"xacro expansion failed: {why}", file=p)
    if len(out) > XACRO_MAX_OUTPUT:
        raise InputError(f"xacro output is larger than {XACRO_MAX_OUTPUT} bytes", file=p)
    return out
