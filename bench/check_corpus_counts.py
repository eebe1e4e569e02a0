"""Findings per rule of `armcli check` on the example-robot-data URDFs, before vs after.

`python bench/check_corpus_counts.py --save FILE` writes {rule: count} (plus the number
of unusable files) for the armcli importable from the current interpreter;
`--compare BEFORE AFTER` prints a Markdown table of the rules whose counts differ.
To record "before", run --save with PYTHONPATH pointing at an older checkout's src/.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import sys
from collections import Counter
from pathlib import Path


def corpus() -> list[Path]:
    """Every robots/**/*.urdf shipped by the example-robot-data distribution."""
    dist = importlib.metadata.distribution("example-robot-data")
    files = [Path(str(dist.locate_file(f))) for f in dist.files or () if str(f).endswith(".urdf")]
    return sorted(p for p in files if "/robots/" in p.as_posix())


def run() -> dict[str, object]:
    """Rule id -> number of findings (`(unusable)` counts exit-2 files), and every finding
    as "robot-path rule line" so that a diff names the findings that changed."""
    from armcli.errors import ArmcliError

    try:  # the package layout since the subpackage refactor
        from armcli.check.options import CheckOptions
        from armcli.check.run import check_urdf
        from armcli.urdf.read import read_urdf
    except ImportError:  # an older checkout's flat modules (for the "before" counts)
        from armcli.checks import CheckOptions, check_urdf  # type: ignore[no-redef]
        from armcli.urdfxml import read_urdf  # type: ignore[no-redef]

    totals: Counter[str] = Counter()
    keys: list[str] = []
    files = corpus()
    for path in files:
        name = path.as_posix().split("/robots/", 1)[1]
        try:
            result = check_urdf(read_urdf(path), CheckOptions())
        except ArmcliError:
            totals["(unusable)"] += 1
            continue
        totals.update(f.rule for f in result.findings)
        keys.extend(f"{name} {f.rule} {f.line}" for f in result.findings)
    totals["(files)"] = len(files)
    return {"counts": dict(sorted(totals.items())), "findings": keys}


def changed(before: list[str], after: list[str]) -> str:
    """The findings only one side has, one line each with - or +."""
    b, a = Counter(before), Counter(after)
    lines = [f"- {k}" for k in sorted((b - a).elements())]
    lines += [f"+ {k}" for k in sorted((a - b).elements())]
    return "".join(line + "\n" for line in lines)


def table(before: dict[str, int], after: dict[str, int], changed_only: bool) -> str:
    rows = ["| rule | before | after | change |", "|---|---:|---:|---:|"]
    for rule in sorted(set(before) | set(after)):
        b, a = before.get(rule, 0), after.get(rule, 0)
        if changed_only and a == b:
            continue
        rows.append(f"| `{rule}` | {b} | {a} | {a - b:+d} |")
    return "\n".join(rows) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--save", type=Path, help="write the counts of this armcli as JSON")
    ap.add_argument("--compare", nargs=2, type=Path, metavar=("BEFORE", "AFTER"))
    ap.add_argument("--all", action="store_true", help="list unchanged rules too")
    ap.add_argument("--diff", action="store_true", help="also list each changed finding")
    args = ap.parse_args(argv)
    if args.save:
        args.save.write_text(json.dumps(run(), indent=1) + "\n")
    if args.compare:
        before, after = (json.loads(p.read_text()) for p in args.compare)
        sys.stdout.write(table(before["counts"], after["counts"], changed_only=not args.all))
        if args.diff:
            sys.stdout.write(changed(before["findings"], after["findings"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
