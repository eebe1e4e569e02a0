"""A one-line status on stderr when a command has printed nothing for STATUS_AFTER_S.

Under load, `check`, `import`, `render` and `view` spend seconds loading Pinocchio, the
model or a browser before their first line (issue 31: 9-48 s, nothing printed until the
end). At a terminal, a command silent for STATUS_AFTER_S gets one line saying it is
working; once anything is written the status is never printed. Into a file or a pipe
nothing is added, so logs and tests see exactly the command's own output.
"""

from __future__ import annotations

import sys
import threading
from typing import IO, Any

STATUS_AFTER_S = 2.0  # [s] of silence before the status line
QUIET = ("--help", "-h", "--version")  # answered at once: never a status


class _Watched:
    """A text stream that remembers whether anything was written to it."""

    def __init__(self, stream: IO[str], seen: threading.Event) -> None:
        self._stream, self._seen = stream, seen

    def write(self, text: str) -> int:
        if text:
            self._seen.set()
        return self._stream.write(text)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


class Status:
    """Print `armcli CMD: working...` once if the command stays silent; see the module."""

    def __init__(self, command: str, err: IO[str], after: float | None = None) -> None:
        self.command, self.err = command, err
        self.after = STATUS_AFTER_S if after is None else after
        self.seen = threading.Event()
        self.timer = threading.Timer(self.after, self._say)
        self.timer.daemon = True

    def _say(self) -> None:
        if not self.seen.is_set():
            self.err.write(
                f"armcli {self.command}: working... (loading the model and its libraries; "
                "the first run after an install is the slowest)\n"
            )
            self.err.flush()

    def watch(self, stream: IO[str]) -> IO[str]:
        """`stream`, wrapped so that writing to it cancels the status."""
        return _Watched(stream, self.seen)  # type: ignore[return-value]

    def start(self) -> None:
        """Start the silence timer."""
        self.timer.start()

    def stop(self) -> None:
        """The command ended: no status from now on."""
        self.seen.set()
        self.timer.cancel()


def start_status(args: list[str]) -> Status | None:
    """A running Status for an interactive command run (stderr a terminal), else None."""
    isatty = getattr(sys.stderr, "isatty", None)
    command = next((a for a in args if not a.startswith("-")), None)
    if command is None or any(a in QUIET for a in args) or not (isatty and isatty()):
        return None
    status = Status(command, sys.stderr)
    sys.stdout = status.watch(sys.stdout)
    sys.stderr = status.watch(sys.stderr)
    status.start()
    return status
