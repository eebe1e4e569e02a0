"""`armcli check --format sarif`: SARIF 2.1.0 for GitHub code scanning and other viewers.

Why SARIF next to `--format github`: workflow annotations vanish with the run, while a
SARIF file uploaded with `github/codeql-action/upload-sarif` becomes code-scanning alerts
that persist, are tracked across commits (`partialFingerprints`) and are closed when the
problem is fixed. The document lists every rule of the registry (`armcli.check.rules.RULES`) in
`tool.driver.rules`, so a viewer can explain rules that did not fire too.

Locations are repository-relative (`uriBaseId` `%SRCROOT%`, relative to `root`, the
current directory by default); files outside `root` get absolute `file://` URIs.
Findings in a URDF built in memory from a spec point at the spec without a line, as
`--format github` does. Output is deterministic: no timestamps, no absolute paths for
files under `root`, stable key order.
"""

from __future__ import annotations

import hashlib
import os
import re
from collections import Counter
from collections.abc import Sequence
from pathlib import Path, PurePosixPath
from typing import Any
from urllib.parse import quote

from armcli import __version__
from armcli.check.findings import Finding
from armcli.check.rules import RULES, Rule
from armcli.errors import split_source
from armcli.io.jsondoc import dumps
from armcli.io.oneline import decodable

SARIF_VERSION = "2.1.0"
SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
SRCROOT = "%SRCROOT%"
FINGERPRINT_KEY = "armcliFinding/v1"
# Values that name the thing a finding is about; they identify it across edits that
# move lines or change numbers, which is what partialFingerprints are for.
_SUBJECT_KEYS = ("link", "joint", "material", "name", "pose", "link1", "link2")
_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def _rule_descriptor(rule: Rule) -> dict[str, Any]:
    """One reportingDescriptor: id, short description, help text, default level."""
    return {
        "id": rule.id,
        "name": "".join(w.capitalize() for w in rule.id.split("-")),
        "shortDescription": {"text": rule.title},
        "fullDescription": {"text": f"{rule.title} ({rule.severity})."},
        "help": {
            "text": f"Fix: {rule.hint}. Rule reference: docs/check.md, rule `{rule.id}`.",
            "markdown": f"**Fix:** {rule.hint}.\n\nSee `docs/check.md`, rule `{rule.id}`.",
        },
        "defaultConfiguration": {"level": rule.severity},
        "properties": {"tags": ["urdf", "robotics"]},
    }


def artifact_uri(path: str, root: Path) -> tuple[str, bool]:
    """(URI, relative?): a POSIX path relative to root when the file is under it."""
    absolute = Path(os.path.abspath(path))  # as the user named it: symlinks kept
    for a, r in ((absolute, Path(os.path.abspath(root))), (absolute.resolve(), root.resolve())):
        if a.is_relative_to(r):  # the name's bytes: a non-UTF-8 one is %FF, not an error
            return quote(os.fsencode(PurePosixPath(*a.relative_to(r).parts).as_posix())), True
    return absolute.resolve().as_uri(), False


def _subject(f: Finding) -> str:
    named = [f"{k}={f.values[k]}" for k in _SUBJECT_KEYS if k in f.values]
    return ",".join(named) if named else _NUMBER.sub("#", f.message)


def _place(path: str, line: int, root: Path) -> dict[str, Any]:
    uri, relative = artifact_uri(path, root)
    artifact: dict[str, Any] = {"uri": uri}
    if relative:
        artifact["uriBaseId"] = SRCROOT
    return {"physicalLocation": {"artifactLocation": artifact, "region": {"startLine": line}}}


def _location(f: Finding, root: Path) -> tuple[dict[str, Any], str]:
    if f.origin is not None:  # a xacro element: the file and line the user wrote
        return _place(f.origin.file, f.origin.line, root), ""
    path, inner = split_source(f.file)
    uri, relative = artifact_uri(path, root)
    artifact: dict[str, Any] = {"uri": uri}
    if relative:
        artifact["uriBaseId"] = SRCROOT
    physical: dict[str, Any] = {"artifactLocation": artifact}
    if f.line and f.line > 0 and not inner:
        physical["region"] = {"startLine": f.line}
    prefix = f"{inner}:{f.line}: " if inner and f.line else (f"{inner}: " if inner else "")
    if f.spec is not None:  # the spec field's line; the generated URDF's in the message
        if f.spec.line:
            physical["region"] = {"startLine": f.spec.line}
        prefix = f"{f.spec.field} ({prefix.rstrip(': ')}): "
    return {"physicalLocation": physical}, prefix


def to_sarif(findings: Sequence[Finding], root: Path | None = None) -> str:
    """The SARIF 2.1.0 log of one `check` run (findings after --ignore/--strict)."""
    base = root if root is not None else Path.cwd()
    index = {rule_id: i for i, rule_id in enumerate(RULES)}
    seen: Counter[str] = Counter()
    results = []
    for f in findings:
        location, prefix = _location(f, base)
        uri = location["physicalLocation"]["artifactLocation"]["uri"]
        key = f"{f.rule}|{uri}|{split_source(f.file)[1]}|{_subject(f)}"
        seen[key] += 1  # the n-th finding with the same subject in the same file
        digest = hashlib.sha256(f"{key}|{seen[key]}".encode()).hexdigest()
        result: dict[str, Any] = {
            "ruleId": f.rule,
            "ruleIndex": index[f.rule],
            "level": f.severity,
            "message": {"text": decodable(f"{prefix}{f.message}{f.calls_text}")},
            "locations": [location],
            "partialFingerprints": {FINGERPRINT_KEY: digest},
            "properties": {"values": dict(f.values), "fix": dict(f.fix), "hint": f.hint},
        }
        if f.origin is not None and f.origin.calls:  # the macro calls, innermost first
            result["relatedLocations"] = [
                {**_place(file, line, base), "id": k, "message": {"text": "macro call"}}
                for k, (file, line) in enumerate(f.origin.calls)
            ]
        results.append(result)
    doc = {
        "$schema": SARIF_SCHEMA,
        "version": SARIF_VERSION,
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "armcli",
                        "version": __version__,
                        "semanticVersion": __version__,
                        "rules": [_rule_descriptor(r) for r in RULES.values()],
                    }
                },
                "columnKind": "unicodeCodePoints",
                "results": results,
            }
        ],
    }
    return dumps(doc)
