"""JSON documents armcli writes (check's JSON, SARIF): strict JSON, non-finite numbers as text.

JSON has no NaN or infinity, and Python's json module writes them as bare tokens other
readers refuse; armcli writes them as the strings "nan", "inf", "-inf" instead.
"""

from __future__ import annotations

import json
import math
from typing import Any


def json_safe(x: Any) -> Any:
    """`x` with non-finite floats as strings and tuples as lists, recursively."""
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [json_safe(v) for v in x]
    return x


def dumps(doc: Any) -> str:
    """The document as indented strict JSON text with a final newline."""
    return json.dumps(json_safe(doc), indent=2, allow_nan=False) + "\n"
