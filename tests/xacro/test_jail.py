"""`--trust-xacro` in the bubblewrap sandbox (xacro_jail): the hostile xacros of issue 15.

Each file runs Python through xacro's `$(eval ...)` (full builtins) and tries
one escape the audit found working in the old rlimit-only child: a forked
`setsid` child outliving the timeout, writing a file through `mmap`, renaming
and symlinking, three forks of 700 MB past the memory limit, 1.5 GB on stdout
(armcli itself peaked at 2.9 GB) and reading the parent's environment through
/proc. The expected values are the sandbox's guarantees (docs/security.md).

Issue 20: run as root, bubblewrap kept every capability inside the sandbox
(CapEff 0x1fffeffffff, uid 0), so the file could remount the read-only binds
writable and change host files, unmount /proc to see the host's processes, and
connect to host unix sockets on the read-only bind of `/`. The `jail` tests run
each escape both as the invoking user (root on CI) and as an ordinary user
(created with useradd when the tests run as root) through the real CLI.
"""

from __future__ import annotations

import html
import os
import resource
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

import armcli.xacro.sandbox as sandbox
from armcli.errors import InputError, XacroRefusedError
from armcli.urdf.source import read_urdf_file
from armcli.xacro.jail import readable_binds, sandbox_problem
from armcli.xacro.sandbox import XACRO_MAX_OUTPUT, XACRO_TIMEOUT, expand_untrusted
from tests.helpers import ROOT, run_cli
from tests.urdf.ordinary_user import ordinary_user

pytestmark = pytest.mark.skipif(
    sandbox_problem() is not None, reason=f"no bubblewrap sandbox here: {sandbox_problem()}"
)
FAST_S = XACRO_TIMEOUT / 2  # a refused escape ends long before the wall-clock limit
RSS_GROWTH_LIMIT_KB = 200_000  # the output cap is 10 MB; before, a 1.5 GB flood was buffered
NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def hostile(tmp_path: Path, code: str, name: str = "evil.xacro") -> Path:
    """A xacro whose link name is the value of `out` after running `code` (no dunders)."""
    expr = f"(lambda g: (exec({code!r}, g), str(g.get('out', 'ran')))[1])({{}})"
    path = tmp_path / name
    path.write_text(  # xacro's lexer ends $(...) at the first ")": the code is a property
        f'<?xml version="1.0"?>\n<robot name="r" {NS}>\n'
        f'  <xacro:property name="code" value="{html.escape(expr, quote=True)}"/>\n'
        '  <link name="$(eval ${code})"/>\n</robot>\n'
    )
    return path


def test_harmless_code_still_runs(tmp_path: Path) -> None:
    out = expand_untrusted(hostile(tmp_path, "out = 6 * 7"))
    assert b'<link name="42"/>' in out


def test_fork_and_setsid_cannot_outlive_the_sandbox(tmp_path: Path) -> None:
    code = (
        "import os, time\nif os.fork() == 0:\n    os.setsid()\n    time.sleep(120)\nout = 'parent'"
    )
    start = time.monotonic()
    with pytest.raises(InputError, match=r"PermissionError|Operation not permitted"):
        expand_untrusted(hostile(tmp_path, code))
    assert time.monotonic() - start < FAST_S  # before: armcli returned after 75 s


def test_fork_memory_cannot_add_up(tmp_path: Path) -> None:
    code = (
        "import os, time\nfor i in range(3):\n    if os.fork() == 0:\n"
        "        b = bytearray(700 * 2**20)\n        time.sleep(5)\n        os._exit(0)\nout = 'x'"
    ).replace("os._exit", "os.abort")  # no dunder-free _exit needed: fork is refused first
    with pytest.raises(InputError, match=r"PermissionError|Operation not permitted"):
        expand_untrusted(hostile(tmp_path, code))


@pytest.mark.parametrize(
    "code",
    [
        "import mmap\nf = open(VICTIM, 'r+b')\nm = mmap.mmap(f.fileno(), 0)\n"
        "m[0:5] = b'owned'\nm.flush()",
        "import os\nos.rename(VICTIM, VICTIM + '.moved')",
        "import os\nos.symlink('/etc/passwd', VICTIM + '.link')",
        "open(VICTIM, 'w').write('owned')",
    ],
    ids=["mmap-write", "rename", "symlink", "write"],
)
def test_no_file_can_change(code: str, tmp_path: Path) -> None:
    victim = tmp_path / "victim.txt"
    victim.write_text("hello world")
    path = hostile(tmp_path, code.replace("VICTIM", repr(str(victim))))
    with pytest.raises(InputError, match=r"Read-only file system|OSError|PermissionError"):
        expand_untrusted(path)
    assert victim.read_text() == "hello world"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["evil.xacro", "victim.txt"]


def test_stdout_flood_is_capped_while_streaming(tmp_path: Path) -> None:
    code = (
        "import sys\nchunk = b'x' * 2**20\nfor i in range(1500):\n"
        "    sys.stdout.buffer.write(chunk)"
    )
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # [KiB] peak so far
    with pytest.raises(InputError, match=f"output is larger than {XACRO_MAX_OUTPUT} bytes"):
        expand_untrusted(hostile(tmp_path, code))
    growth = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert growth < RSS_GROWTH_LIMIT_KB, growth


def test_parent_environment_is_not_readable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("SECRET_TOKEN", "hunter2-issue15")
    code = (
        "import os\nseen = []\nfor p in os.listdir('/proc'):\n    if p.isdigit():\n"
        "        try:\n            seen.append(open('/proc/' + p + '/environ').read())\n"
        "        except OSError:\n            pass\n"
        "out = ' '.join(seen).replace(chr(0), ' ') + ' pid ' + str(os.getppid())"
    )
    out = expand_untrusted(hostile(tmp_path, code))
    assert b"hunter2" not in out and b"SECRET_TOKEN" not in out
    assert b"pid 0" in out or b"pid 1" in out  # a new PID namespace: armcli is not visible


def test_no_network(tmp_path: Path) -> None:
    code = (
        "import socket\ns = socket.create_connection(('1.1.1.1', 53), timeout=2)\nout = 'connected'"
    )
    with pytest.raises(InputError, match=r"OSError|unreachable|Network"):
        expand_untrusted(hostile(tmp_path, code))


def test_refused_without_sandbox_unless_unsandboxed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sandbox, "sandbox_problem", lambda: "bubblewrap (bwrap) is not installed")
    path = hostile(tmp_path, "out = 'ok'")
    with pytest.raises(
        XacroRefusedError, match=r"install the Debian package bubblewrap.*unsandboxed"
    ):
        expand_untrusted(path)
    assert b'<link name="ok"/>' in expand_untrusted(path, unsandboxed=True)


def test_cli_spelling_trust_xacro_unsandboxed(tmp_path: Path, root: Path) -> None:
    path = hostile(tmp_path, "out = 'ok'")
    for flag in ("--trust-xacro", "--trust-xacro=unsandboxed"):
        proc = run_cli(["tree", flag, path], root, {"SECRET_TOKEN": "x"})
        assert proc.returncode == 0, proc.stderr
        assert "ok" in proc.stdout


# --- issue 20: the same escapes as root and as an ordinary user -------------------------

SANDBOX_IDENTITY = "uid65534_gid65534_cap0000000000000000"  # xacro_jail.SANDBOX_UID, no caps
MAX_SANDBOX_PIDS = 3  # bubblewrap's init and the interpreter (before: 121 host processes)
CLI_TIMEOUT_S = 120
MS_BIND, MS_REMOUNT, MNT_DETACH = 4096, 32, 2  # linux/mount.h
LIBC = "import ctypes\nlibc = ctypes.CDLL(None, use_errno=True)\n"


@dataclass(frozen=True)
class Jail:
    """Where a test's files live, and how armcli expands them (ok, output or error line)."""

    dir: Path
    expand: Callable[[Path], tuple[bool, str]]


def _in_process(path: Path) -> tuple[bool, str]:
    try:
        return True, expand_untrusted(path).decode()
    except InputError as exc:
        return False, str(exc)


@pytest.fixture(params=["invoker", "ordinary-user"])
def jail(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Jail]:
    """`invoker`: the library as the user running the tests (root on CI); `ordinary-user`:
    `armcli tree --trust-xacro` through the CLI as a non-root user."""
    if request.param == "invoker":
        yield Jail(tmp_path, _in_process)
        return
    user = ordinary_user()
    if isinstance(user, str):
        pytest.skip(f"cannot run as an ordinary user here: {user}")
    work = Path(tempfile.mkdtemp(prefix="armcli-jail-"))  # pytest's tmp_path is private to root
    work.chmod(0o755)

    def as_user(path: Path) -> tuple[bool, str]:
        user.own(work)
        proc = subprocess.run(
            [*user.prefix, sys.executable, "-m", "armcli.cli", "tree", "--trust-xacro", str(path)],
            capture_output=True,
            text=True,
            timeout=CLI_TIMEOUT_S,
            check=False,
            cwd=ROOT,
            env={"PATH": os.environ["PATH"], "HOME": str(work), "LANG": "C.UTF-8"},
        )
        if "cannot run here" in proc.stderr:
            pytest.skip(f"no bubblewrap sandbox for an ordinary user: {proc.stderr.strip()}")
        return proc.returncode == 0, proc.stdout if proc.returncode == 0 else proc.stderr

    try:
        yield Jail(work, as_user)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def test_child_is_unprivileged(jail: Jail) -> None:
    code = (
        "import os\ncap = [ln.split()[1] for ln in open('/proc/self/status') "
        "if ln.startswith('CapEff')][0]\n"
        "out = f'uid{os.getuid()}_gid{os.getgid()}_cap{cap}'"
    )
    ok, said = jail.expand(hostile(jail.dir, code))
    assert ok, said
    assert SANDBOX_IDENTITY in said  # before, as root: uid0 and cap000001fffeffffff


@pytest.mark.parametrize(
    "action",
    [
        "import mmap\nf = open(VICTIM, 'r+b')\nm = mmap.mmap(f.fileno(), 0)\n"
        "m[0:5] = b'owned'\nm.flush()",
        "import os\nos.rename(VICTIM, VICTIM + '.moved')",
        "import os\nos.symlink('/etc/passwd', VICTIM + '.link')",
        "open(VICTIM, 'w').write('owned')",
    ],
    ids=["mmap-write", "rename", "symlink", "write"],
)
def test_binds_cannot_be_remounted_writable(action: str, jail: Jail) -> None:
    victim = jail.dir / "victim.txt"
    victim.write_text("hello world")
    remount = (
        f"for target in (DIR, '/'):\n"
        f"    libc.mount(None, target.encode(), None, {MS_BIND | MS_REMOUNT}, None)\n"
    )
    code = (LIBC + remount + action).replace("VICTIM", repr(str(victim)))
    ok, said = jail.expand(hostile(jail.dir, code.replace("DIR", repr(str(jail.dir)))))
    assert not ok, said  # before, as root: the remount succeeded and so did the write
    assert victim.read_text() == "hello world"
    assert sorted(p.name for p in jail.dir.iterdir()) == ["evil.xacro", "victim.txt"]


def test_host_proc_is_not_reachable(jail: Jail) -> None:
    code = LIBC + (
        "libc.umount2(b'/proc', MNT_DETACH)\nimport os\n"
        "pids = [p for p in os.listdir('/proc') if p.isdigit()] if os.path.isdir('/proc') else []\n"
        "out = 'pids' + str(len(pids))"
    ).replace("MNT_DETACH", str(MNT_DETACH))
    ok, said = jail.expand(hostile(jail.dir, code))
    assert ok, said
    seen = int(said.split("pids", 1)[1].split()[0].strip("\"'<>/"))
    assert seen <= MAX_SANDBOX_PIDS, said  # before, as root: every host process


def test_host_files_outside_the_binds_are_not_visible(jail: Jail) -> None:
    elsewhere = Path(tempfile.mkdtemp(dir="/var/tmp"))
    try:
        (elsewhere / "secret.txt").write_text("hunter2")
        hidden = ["/etc/shadow", "/etc/passwd", "/run", str(elsewhere / "secret.txt")]
        code = f"import os\nout = 'seen_' + '_'.join(p for p in {hidden!r} if os.path.exists(p))"
        ok, said = jail.expand(hostile(jail.dir, code))
    finally:
        shutil.rmtree(elsewhere)
    assert ok, said
    assert "seen_" in said and "seen_/" not in said, said  # before: every one of them


@pytest.mark.parametrize("where", ["beside-the-file", "elsewhere"])
def test_no_unix_socket_is_reachable(where: str, jail: Jail) -> None:
    folder = jail.dir if where == "beside-the-file" else Path(tempfile.mkdtemp(dir="/var/tmp"))
    folder.chmod(0o755)
    path = folder / "s"
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        listener.bind(str(path))
        path.chmod(0o777)  # any local user may connect: only the sandbox stands in the way
        listener.listen(1)
        listener.setblocking(False)
        code = (
            "import socket\ns = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)\n"
            f"s.connect({str(path)!r})\ns.sendall(b'hello')\nout = 'connected'"
        )
        ok, said = jail.expand(hostile(jail.dir, code))
        assert not ok and "PermissionError" in said, said  # socket(AF_UNIX) refused by seccomp
        with pytest.raises(BlockingIOError):
            listener.accept()  # before: the sandbox connected and sent data
    finally:
        listener.close()
        path.unlink(missing_ok=True)
        if folder != jail.dir:
            shutil.rmtree(folder, ignore_errors=True)


def test_bind_list_keeps_outermost_real_directories(tmp_path: Path) -> None:
    (tmp_path / "pkg" / "urdf").mkdir(parents=True)
    (tmp_path / "link").symlink_to(tmp_path / "pkg")
    binds = readable_binds(
        [tmp_path / "pkg" / "urdf", tmp_path / "link", tmp_path / "missing", Path("/")]
    )
    assert binds == [tmp_path / "pkg"]  # nested and symlinked duplicates, "/" and absent dropped


def test_package_of_the_file_is_readable(tmp_path: Path) -> None:
    """Only the file's directory and its package are bound: a `../` include still works."""
    pkg = tmp_path / "my_pkg"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "common").mkdir()
    (pkg / "package.xml").write_text("<package><name>my_pkg</name></package>\n")
    (pkg / "common" / "part.xacro").write_text(f'<robot {NS}><link name="from_common"/></robot>\n')
    main = pkg / "urdf" / "robot.xacro"
    main.write_text(
        f'<robot name="r" {NS}><xacro:include filename="../common/part.xacro"/></robot>\n'
    )
    doc = read_urdf_file(main, trust_xacro=True)
    assert b'<link name="from_common"/>' in doc.text


@pytest.mark.parametrize("unsandboxed", [False, True], ids=["sandbox", "unsandboxed"])
def test_timeout_holds_when_the_file_closes_its_output(unsandboxed: bool, tmp_path: Path) -> None:
    """Issue 20: closing stdout and stderr, then sleeping, made armcli wait 91 s."""
    code = "import os, time\nos.close(1)\nos.close(2)\ntime.sleep(60)"
    start = time.monotonic()
    with pytest.raises(InputError, match="took longer than 2 s"):
        expand_untrusted(hostile(tmp_path, code), timeout=2.0, unsandboxed=unsandboxed)
    assert time.monotonic() - start < FAST_S  # before: "failed: None" after the sleep


def test_silent_failure_says_its_exit_status(tmp_path: Path) -> None:
    code = "import os\nos.close(2)\nraise SystemExit(3)"
    with pytest.raises(InputError, match=r"failed: exit status \d+, no message"):
        expand_untrusted(hostile(tmp_path, code), unsandboxed=True)  # before: "failed: None"
