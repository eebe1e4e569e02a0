"""The bubblewrap sandbox around `--trust-xacro` (xacro itself, which runs the file's Python).

What the sandbox gives the child (see docs/security.md):

- the whole filesystem read-only (`--ro-bind / /`), a private empty /tmp and
  a minimal /dev, so no file outside can be written, renamed, linked or
  changed through a writable mmap; the xacro file's directory is bound back
  read-only when it lies under /tmp;
- no network (`--unshare-net`) and new user, IPC, UTS, cgroup and PID
  namespaces: a fresh /proc shows only the sandbox, so the parent's
  `/proc/<pid>/environ` cannot be read, and every process dies with the
  sandbox's init (`--die-with-parent` ties that to armcli);
- an empty environment (`--clearenv`) plus PATH, LANG and ROS_PACKAGE_PATH;
- a seccomp filter that makes fork, vfork, clone and clone3 fail with EPERM:
  the child cannot have descendants, so the per-process limits (CPU, address
  space, file size, open files; xacro_sandbox.limit_child) bound the whole
  sandbox even where no cgroup can be created (the descendant count is 0);
- stdout and stderr read with a streaming cap, and a wall-clock timeout
  that kills the sandbox (xacro_sandbox.run_limited).

Where bubblewrap is missing or cannot create namespaces, `sandbox_problem`
says why and `--trust-xacro` is refused unless `--trust-xacro=unsandboxed`.
"""

from __future__ import annotations

import functools
import os
import platform
import shutil
import struct
import subprocess
from collections.abc import Iterable, Mapping
from pathlib import Path

PROBE_TIMEOUT_S = 10.0
# seccomp BPF (linux/filter.h, linux/seccomp.h, linux/audit.h)
_LD_W_ABS, _JEQ_K, _JGE_K, _RET_K = 0x20, 0x15, 0x35, 0x06
_RET_ALLOW, _RET_KILL = 0x7FFF0000, 0x80000000
_RET_EPERM = 0x00050000 | 1
_X32_BIT = 0x40000000
# architecture -> (AUDIT_ARCH_*, syscall numbers that create processes or threads)
_ARCHES = {
    "x86_64": (0xC000003E, (56, 57, 58, 435)),  # clone, fork, vfork, clone3
    "aarch64": (0xC00000B7, (220, 435)),  # clone, clone3
}


def seccomp_program(machine: str | None = None) -> bytes | None:
    """A BPF program refusing every way to create a process (None: unknown architecture)."""
    arch = _ARCHES.get(machine or platform.machine())
    if arch is None:
        return None
    audit, numbers = arch
    n = len(numbers)
    prog = [
        (_LD_W_ABS, 0, 0, 4),  # A = seccomp_data.arch
        (_JEQ_K, 1, 0, audit),
        (_RET_K, 0, 0, _RET_KILL),  # another ABI (e.g. 32-bit int 0x80): kill
        (_LD_W_ABS, 0, 0, 0),  # A = seccomp_data.nr
        (_JGE_K, n + 1, 0, _X32_BIT),  # x32 syscalls: refuse
    ]
    for i, nr in enumerate(numbers):
        prog.append((_JEQ_K, n - i, 0, nr))  # jump to the EPERM return
    prog += [(_RET_K, 0, 0, _RET_ALLOW), (_RET_K, 0, 0, _RET_EPERM)]
    return b"".join(struct.pack("=HBBI", *ins) for ins in prog)


@functools.cache
def sandbox_problem() -> str | None:
    """Why bubblewrap cannot sandbox here (None when it can); probed once per process."""
    bwrap = shutil.which("bwrap")
    if bwrap is None:
        return "bubblewrap (bwrap) is not installed"
    if seccomp_program() is None:
        return f"no seccomp filter for the {platform.machine()} architecture"
    try:
        proc = subprocess.run(
            [bwrap, *_ISOLATION, "--", "/bin/true"],
            capture_output=True,
            timeout=PROBE_TIMEOUT_S,
            check=False,
        )
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"bwrap cannot run: {exc}"
    if proc.returncode != 0:
        said = proc.stderr.decode("utf-8", "replace").strip().splitlines()
        return f"bwrap cannot create its namespaces ({said[-1] if said else proc.returncode})"
    return None


_ISOLATION = (
    "--ro-bind",
    "/",
    "/",
    "--dev",
    "/dev",
    "--proc",
    "/proc",
    "--tmpfs",
    "/tmp",
    "--unshare-all",
    "--die-with-parent",
    "--new-session",
    "--clearenv",
)


def jail_argv(
    argv: Iterable[str],
    *,
    binds: Iterable[Path],
    env: Mapping[str, str],
    cwd: Path,
    seccomp_fd: int,
) -> list[str]:
    """The bwrap command line running `argv` inside the sandbox described above."""
    bwrap = shutil.which("bwrap") or "bwrap"
    out = [bwrap, *_ISOLATION]
    for d in sorted({Path(os.path.realpath(b)) for b in binds}):
        if d.is_relative_to("/tmp"):  # hidden by the private /tmp: bind it back read-only
            out += ["--ro-bind", str(d), str(d)]
    for key, value in sorted(env.items()):
        out += ["--setenv", key, value]
    out += ["--chdir", str(cwd), "--seccomp", str(seccomp_fd), "--", *argv]
    return out
