"""`--trust-xacro` in the bubblewrap sandbox (xacro_jail): the hostile xacros of issue 15.

Each file runs Python through xacro's `$(eval ...)` (full builtins) and tries
one escape the audit found working in the old rlimit-only child: a forked
`setsid` child outliving the timeout, writing a file through `mmap`, renaming
and symlinking, three forks of 700 MB past the memory limit, 1.5 GB on stdout
(armcli itself peaked at 2.9 GB) and reading the parent's environment through
/proc. The expected values are the sandbox's guarantees (docs/security.md).
"""

from __future__ import annotations

import html
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

import armcli.urdf.xacro_sandbox as sandbox
from armcli.errors import InputError, XacroRefusedError
from armcli.urdf.xacro_jail import sandbox_problem
from armcli.urdf.xacro_sandbox import XACRO_MAX_OUTPUT, XACRO_TIMEOUT, expand_untrusted

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
        proc = subprocess.run(
            [sys.executable, "-m", "armcli.cli", "tree", flag, str(path)],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
            cwd=root,
            env={**os.environ, "SECRET_TOKEN": "x"},
        )
        assert proc.returncode == 0, proc.stderr
        assert "ok" in proc.stdout
