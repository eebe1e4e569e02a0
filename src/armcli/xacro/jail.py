"""The bubblewrap sandbox around `--trust-xacro` (xacro itself, which runs the file's Python).

What the sandbox gives the child, whoever runs armcli (root included; see
docs/security.md):

- an unprivileged identity: a new user namespace where the child is uid/gid
  65534 with every capability dropped (`--cap-drop ALL`; CapEff 0). As root,
  bubblewrap otherwise keeps every capability inside, and the file could
  remount the read-only binds writable, unmount /proc, and so on;
- a filesystem built from nothing: a tmpfs root holding only the system
  directories the interpreter needs (`/usr`, `/lib*`, `/bin`, ...), the
  interpreter's own directories and the directories the file may read
  (`readable`), all read-only; a private empty /tmp, a minimal /dev and a
  fresh /proc. No home directory, /etc, /run or host socket is visible;
- no network (`--unshare-net`) and new IPC, UTS, cgroup and PID namespaces:
  /proc shows only the sandbox, and every process dies with the sandbox's
  init (`--die-with-parent` ties that to armcli);
- an empty environment (`--clearenv`) plus what the caller passes;
- a seccomp filter (`seccomp_program`) refusing with EPERM: process creation
  (fork, vfork, clone, clone3: the child has no descendants, so the
  per-process limits in xacro.sandbox.limit_child bound the whole sandbox),
  unix sockets (`socket`/`socketpair` with AF_UNIX: a bound directory may
  hold a socket of a host service), new namespaces (`unshare`, `setns`),
  mount operations, ptrace, keyrings, bpf, perf events, userfaultfd and
  io_uring (whose operations bypass seccomp);
- stdout and stderr read with a streaming cap, and a wall-clock timeout
  that kills the sandbox (xacro.sandbox.run_limited).

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
SANDBOX_UID = SANDBOX_GID = 65534  # "nobody": no file on the host is owned by it inside
# What the interpreter needs from the host, read-only (absent ones are skipped; the
# top-level symlinks of a merged /usr are recreated as symlinks).
SYSTEM_PATHS = (
    "/usr",
    "/bin",
    "/sbin",
    "/lib",
    "/lib32",
    "/lib64",
    "/libx32",
    "/etc/ld.so.cache",
    "/etc/ld.so.conf",
    "/etc/ld.so.conf.d",
)
_NAMESPACES = (
    "--unshare-user",
    "--unshare-ipc",
    "--unshare-pid",
    "--unshare-net",
    "--unshare-uts",
    "--unshare-cgroup-try",
    "--uid",
    str(SANDBOX_UID),
    "--gid",
    str(SANDBOX_GID),
    "--cap-drop",
    "ALL",
    "--die-with-parent",
    "--new-session",
    "--clearenv",
)

# seccomp BPF (linux/filter.h, linux/seccomp.h, linux/audit.h)
_LD_W_ABS, _JEQ_K, _JGE_K, _RET_K = 0x20, 0x15, 0x35, 0x06
_RET_ALLOW, _RET_KILL = 0x7FFF0000, 0x80000000
_RET_EPERM = 0x00050000 | 1
_X32_BIT = 0x40000000
_OFF_NR, _OFF_ARCH, _OFF_ARG0 = 0, 4, 16  # struct seccomp_data (arg0's low word: little endian)
_AF_UNIX = 1
# Refused system calls by name; the socket calls are refused for AF_UNIX only.
_REFUSED = (
    *("clone", "fork", "vfork", "clone3"),
    *("unshare", "setns", "mount", "umount2", "pivot_root", "chroot"),
    *("open_tree", "move_mount", "fsopen", "fsconfig", "fsmount", "fspick", "mount_setattr"),
    *("ptrace", "add_key", "request_key", "keyctl", "bpf", "perf_event_open", "userfaultfd"),
    *("io_uring_setup", "io_uring_enter", "io_uring_register"),
)
_SOCKETS = ("socket", "socketpair")
# Numbers since Linux 5.1 are shared by every architecture.
_NEW = {"io_uring_setup": 425, "io_uring_enter": 426, "io_uring_register": 427}
_NEW |= {"open_tree": 428, "move_mount": 429, "fsopen": 430, "fsconfig": 431, "fsmount": 432}
_NEW |= {"fspick": 433, "clone3": 435, "mount_setattr": 442}
# machine -> (AUDIT_ARCH_*, system call numbers)
_ARCHES: dict[str, tuple[int, dict[str, int]]] = {
    "x86_64": (  # asm/unistd_64.h
        0xC000003E,
        {
            **{"socket": 41, "socketpair": 53, "clone": 56, "fork": 57, "vfork": 58},
            **{"ptrace": 101, "pivot_root": 155, "chroot": 161, "mount": 165, "umount2": 166},
            **{"add_key": 248, "request_key": 249, "keyctl": 250, "unshare": 272},
            **{"perf_event_open": 298, "setns": 308, "bpf": 321, "userfaultfd": 323},
            **_NEW,
        },
    ),
    "aarch64": (  # asm-generic/unistd.h (no fork or vfork: clone does both)
        0xC00000B7,
        {
            **{"umount2": 39, "mount": 40, "pivot_root": 41, "chroot": 51, "unshare": 97},
            **{"ptrace": 117, "socket": 198, "socketpair": 199, "add_key": 217},
            **{"request_key": 218, "keyctl": 219, "clone": 220, "perf_event_open": 241},
            **{"setns": 268, "bpf": 280, "userfaultfd": 282},
            **_NEW,
        },
    ),
}


def seccomp_program(machine: str | None = None) -> bytes | None:
    """The BPF program described above (None: unknown architecture)."""
    arch = _ARCHES.get(machine or platform.machine())
    if arch is None:
        return None
    audit, numbers = arch
    refused = [numbers[name] for name in _REFUSED if name in numbers]
    sockets = [numbers[name] for name in _SOCKETS]
    prog: list[tuple[int, int | str, int | str, int] | str] = [
        (_LD_W_ABS, 0, 0, _OFF_ARCH),
        (_JEQ_K, 1, 0, audit),
        (_RET_K, 0, 0, _RET_KILL),  # another ABI (e.g. 32-bit int 0x80): kill
        (_LD_W_ABS, 0, 0, _OFF_NR),
        (_JGE_K, "eperm", 0, _X32_BIT),  # x32 syscalls: refuse
        *((_JEQ_K, "eperm", 0, nr) for nr in refused),
        *((_JEQ_K, "family", 0, nr) for nr in sockets),
        (_RET_K, 0, 0, _RET_ALLOW),
        "family",
        (_LD_W_ABS, 0, 0, _OFF_ARG0),
        (_JEQ_K, "eperm", 0, _AF_UNIX),
        (_RET_K, 0, 0, _RET_ALLOW),
        "eperm",
        (_RET_K, 0, 0, _RET_EPERM),
    ]
    return _assemble(prog)


def _assemble(prog: list[tuple[int, int | str, int | str, int] | str]) -> bytes:
    """Classic BPF with jump targets given as labels (strings) resolved to offsets."""
    labels: dict[str, int] = {}
    code: list[tuple[int, int | str, int | str, int]] = []
    for item in prog:
        if isinstance(item, str):
            labels[item] = len(code)
        else:
            code.append(item)

    def offset(target: int | str, here: int) -> int:
        return target if isinstance(target, int) else labels[target] - here - 1

    return b"".join(
        struct.pack("=HBBI", op, offset(jt, i), offset(jf, i), k)
        for i, (op, jt, jf, k) in enumerate(code)
    )


def readable_binds(paths: Iterable[Path]) -> list[Path]:
    """The real directories (or files) to bind read-only: existing, deduplicated, no nesting."""
    real = sorted({Path(os.path.realpath(p)) for p in paths if os.path.exists(p)})
    kept: list[Path] = []
    for p in real:
        if p != Path("/") and not any(p.is_relative_to(k) for k in kept):
            kept.append(p)
    return kept


def filesystem_args(readable: Iterable[Path]) -> list[str]:
    """The bwrap arguments building the sandbox's filesystem: system paths plus `readable`."""
    out = ["--dev", "/dev", "--proc", "/proc", "--tmpfs", "/tmp"]
    system: list[Path] = []
    for name in SYSTEM_PATHS:
        if os.path.islink(name):
            out += ["--symlink", os.readlink(name), name]
        elif os.path.exists(name):
            system.append(Path(name))
    for d in readable_binds([*system, *readable]):
        out += ["--ro-bind", str(d), str(d)]
    return out


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
            [bwrap, *_NAMESPACES, *filesystem_args([]), "--", "/bin/true"],
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


def jail_argv(
    argv: Iterable[str],
    *,
    readable: Iterable[Path],
    env: Mapping[str, str],
    cwd: Path,
    seccomp_fd: int,
) -> list[str]:
    """The bwrap command line running `argv` inside the sandbox described above.

    `readable`: the directories the child may read besides the system paths (the
    interpreter's, the file's, package roots); each is bound read-only at its real path.
    """
    bwrap = shutil.which("bwrap") or "bwrap"
    out = [bwrap, *_NAMESPACES, *filesystem_args(readable)]
    for key, value in sorted(env.items()):
        out += ["--setenv", key, value]
    out += ["--chdir", str(cwd), "--seccomp", str(seccomp_fd), "--", *argv]
    return out
