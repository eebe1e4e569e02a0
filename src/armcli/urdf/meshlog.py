"""trimesh's complaints while meshes load, as one line per mesh instead of tracebacks.

trimesh logs a missing texture image of a COLLADA mesh (PR2's meshes ship without some)
as a warning with a traceback through Python's last-resort handler: stderr fills with
tracebacks for something that only leaves a mesh uncoloured. While yourdfpy loads the
meshes, these records are kept here, with the URI of the mesh being loaded, and the
caller turns them into one warning each.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager


class MeshLog(logging.Handler):
    """Collects trimesh's WARNING records as mesh URI -> first message."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.current = ""  # the URI of the mesh being loaded (set by the filename handler)
        self.said: dict[str, str] = {}

    def emit(self, record: logging.LogRecord) -> None:
        """Keep the message and the exception's text, never the traceback."""
        text = record.getMessage()
        if record.exc_info and record.exc_info[1] is not None:
            exc = record.exc_info[1]
            text = f"{text}: {type(exc).__name__}: {exc}"
        self.said.setdefault(self.current or "a mesh", text)


@contextmanager
def quiet_trimesh() -> Iterator[MeshLog]:
    """Send the log records of trimesh to a MeshLog for the duration, not to stderr."""
    log = logging.getLogger("trimesh")
    handler = MeshLog()
    propagate = log.propagate
    log.addHandler(handler)
    log.propagate = False
    try:
        yield handler
    finally:
        log.removeHandler(handler)
        log.propagate = propagate
