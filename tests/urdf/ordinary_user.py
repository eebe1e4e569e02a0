"""Run a command as an ordinary (non-root) user, for tests that must hold for root and non-root.

Under root, a system user is created with `useradd` (once; it owns no files) and
commands run through `setpriv`. Where the interpreter lies under a directory
others cannot enter (a pyenv Python in /root, mode 0700), the command runs in a
private mount namespace where that directory is a world-readable tmpfs holding
only the needed entries, bound from the real directory: the user sees exactly
the same interpreter and checkout, nothing else of the directory.
"""

from __future__ import annotations

import os
import pwd
import shutil
import stat
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from tests.helpers import ROOT

USER = "armcli-jailtest"
# (*args, env=None, code=None) -> the finished process: `armcli ARGS`, or `python -c CODE ARGS`
Run = Callable[..., subprocess.CompletedProcess[str]]
_SETUP_TIMEOUT_S = 60


@dataclass(frozen=True)
class OrdinaryUser:
    """A non-root user and the command prefix that runs a program as that user."""

    uid: int
    gid: int
    prefix: tuple[str, ...]

    def own(self, directory: Path) -> None:
        """Give `directory` and everything in it to the user (files the test wrote as root)."""
        if os.geteuid() != 0:
            return
        for path in (directory, *directory.rglob("*")):
            os.chown(path, self.uid, self.gid, follow_symlinks=False)


def _blocked(paths: list[Path]) -> dict[Path, set[str]] | str:
    """Directories others cannot enter on the way to `paths` -> the entries needed in them."""
    blocked: dict[Path, set[str]] = {}
    for target in paths:
        here, seen = Path("/"), False
        for part in target.parts[1:]:
            if not os.stat(here).st_mode & stat.S_IXOTH:
                if seen:
                    return f"{here} and one of its ancestors are both closed to other users"
                blocked.setdefault(here, set()).add(part)
                seen = True
            here = here / part
    return blocked


def _prefix(uid: int, gid: int, blocked: dict[Path, set[str]]) -> tuple[str, ...]:
    become = ("setpriv", f"--reuid={uid}", f"--regid={gid}", "--clear-groups", "--")
    if not blocked:
        return become
    lines = ["set -e"]
    for i, (closed, entries) in enumerate(sorted(blocked.items())):
        fd = 3 + i  # the real directory stays reachable through /proc/self/fd after the tmpfs
        lines += [f'exec {fd}<"{closed}"', f'mount -t tmpfs -o mode=0755 tmpfs "{closed}"']
        for entry in sorted(entries):
            lines += [
                f'mkdir "{closed}/{entry}"',
                f'mount --no-canonicalize --bind "/proc/self/fd/{fd}/{entry}" "{closed}/{entry}"',
            ]
        lines.append(f"exec {fd}<&-")
    lines.append(f'exec {" ".join(become)} "$@"')
    script = "\n".join(lines)
    return ("unshare", "--mount", "--propagation", "private", "bash", "-c", script, "as-user")


def ordinary_user() -> OrdinaryUser | str:
    """The user to run as (the invoking one when it is not root), or why there is none."""
    if os.geteuid() != 0:
        return OrdinaryUser(os.getuid(), os.getgid(), ())
    for tool in ("useradd", "setpriv", "unshare", "bash"):
        if shutil.which(tool) is None:
            return f"{tool} is not installed"
    try:
        pw = pwd.getpwnam(USER)
    except KeyError:
        made = subprocess.run(
            ["useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", USER],
            capture_output=True,
            text=True,
            timeout=_SETUP_TIMEOUT_S,
            check=False,
        )
        if made.returncode != 0:
            return f"useradd {USER} failed: {made.stderr.strip()}"
        pw = pwd.getpwnam(USER)
    needed = [Path(sys.executable), Path(os.path.realpath(sys.executable)), Path(sys.prefix)]
    needed += [Path(sys.base_prefix), ROOT / "src"]
    blocked = _blocked(needed)
    if isinstance(blocked, str):
        return blocked
    return OrdinaryUser(pw.pw_uid, pw.pw_gid, _prefix(pw.pw_uid, pw.pw_gid, blocked))
