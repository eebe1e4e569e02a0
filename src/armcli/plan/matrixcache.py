"""The allowed-collision matrix of a robot without an SRDF, computed once and kept per robot.

`plan` without `--srdf` checks the pairs `ros-package` would write (ros.collision_matrix:
10,000 random states, seconds of work). They depend only on the collision geometry and the
sampling, so they are kept in the user's cache directory (`$ARMCLI_CACHE_DIR`, else
`$XDG_CACHE_HOME/armcli`, else `~/.cache/armcli`) as `acm/<key>.json`. The key is the
SHA-256 of the URDF text the matrix is computed from, the bytes of every collision mesh it
names, the sample count, seed and named poses, Pinocchio's version and the source of the
modules that compute the matrix: any change computes it anew.

A cache file is data, never trusted: it is read with a size cap, parsed as JSON and used
only when it has exactly the expected shape, carries the same key and names links of this
robot; anything else is ignored (and replaced). Nothing in it is run. Writing is atomic and
best effort: a read-only or missing cache directory only means computing every time.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Callable, Collection, Mapping
from pathlib import Path

from armcli.errors import InputError
from armcli.io.files import write_file_atomic
from armcli.io.userfile import read_regular
from armcli.robot import sampling
from armcli.ros import collision_matrix

FORMAT = 1  # bump when the file's shape or meaning changes
MAX_CACHE_BYTES = 4_000_000  # [bytes] a robot of 500 links has ~125,000 pairs at most
Pairs = tuple[tuple[str, str], ...]


def cache_dir() -> Path:
    """Where armcli keeps what it computed before."""
    base = os.environ.get("ARMCLI_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "armcli"
    )
    return Path(base) / "acm"


def matrix_key(
    text: str | bytes, poses: Mapping[str, Mapping[str, float]] | None, samples: int, seed: int
) -> str:
    """SHA-256 over everything the matrix depends on (see the module docstring)."""
    import pinocchio
    from lxml import etree

    h = hashlib.sha256(f"armcli-acm {FORMAT} {samples} {seed} {pinocchio.__version__}\n".encode())
    for module in (collision_matrix, sampling):
        h.update(Path(module.__file__ or "").read_bytes())
    data = text if isinstance(text, bytes) else text.encode("utf-8", "surrogatepass")
    h.update(data)
    root = etree.fromstring(data)
    for mesh in root.iterfind(".//collision//mesh"):
        name = mesh.get("filename") or ""
        h.update(name.encode())
        if os.path.isabs(name) and os.path.isfile(name):  # confined: bounded files
            h.update(hashlib.sha256(Path(name).read_bytes()).digest())
    h.update(json.dumps(poses, sort_keys=True).encode())
    return h.hexdigest()


def _load(path: Path, key: str, links: Collection[str]) -> Pairs | None:
    """The pairs of a cache file that passes every check, else None."""
    try:
        doc = json.loads(read_regular(path, max_bytes=MAX_CACHE_BYTES, what="cache file"))
    except (InputError, ValueError, OSError):
        return None
    if not (isinstance(doc, dict) and set(doc) == {"format", "key", "disabled"}):
        return None
    pairs = doc["disabled"]
    if doc["format"] != FORMAT or doc["key"] != key or not isinstance(pairs, list):
        return None
    out = []
    for pair in pairs:
        if not (isinstance(pair, list) and len(pair) == 2 and all(p in links for p in pair)):
            return None
        out.append((str(pair[0]), str(pair[1])))
    return tuple(out)


def cached_pairs(key: str, links: Collection[str], compute: Callable[[], Pairs]) -> Pairs:
    """The disabled pairs under `key`: from the cache when it holds them, else computed."""
    path = cache_dir() / f"{key}.json"
    found = _load(path, key, set(links))
    if found is not None:
        return found
    pairs = compute()
    doc = {"format": FORMAT, "key": key, "disabled": [list(p) for p in pairs]}
    with contextlib.suppress(OSError):  # no cache: computed again next time
        write_file_atomic(path, json.dumps(doc, indent=0) + "\n")
    return pairs
