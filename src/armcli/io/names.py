"""Did you mean `forearm_hand_joint`? The closest valid name for a misspelt one.

One suggestion rule for joints, links, poses and keys wherever a name is looked up
(spec.suggest applies it to spec keys through the models).
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable

CUTOFF = 0.6  # difflib similarity below which no suggestion is made


def did_you_mean(name: object, valid: Iterable[str]) -> str:
    """`did you mean 'x'? ` (a trailing space, to go before a list of the valid names), or ""."""
    close = difflib.get_close_matches(str(name), sorted(valid), n=1, cutoff=CUTOFF)
    return f"did you mean {close[0]!r}? " if close else ""
