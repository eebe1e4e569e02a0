"""`check --format sarif` through the real CLI, validated against the official SARIF 2.1.0
schema: rules, locations, levels, stable fingerprints, unusable files as results."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from armcli.check.rules import RULES
from tests.cli.test_check import armcli
from tests.helpers import FIXTURES, ROOT, course_gains_spec

# The OASIS TC's schema, verbatim: github.com/oasis-tcs/sarif-spec,
# sarif-2.1/schema/sarif-schema-2.1.0.json at commit e0583813964e (its "id" is the
# errata01 OS URI docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/...).
SCHEMA_PATH = FIXTURES / "sarif" / "sarif-schema-2.1.0.json"
SCHEMA_SHA256 = "c3b4bb2d6093897483348925aaa73af03b3e3f4bd4ca38cef26dcb4212a2682e"


def validate(doc: dict[str, Any]) -> None:
    import jsonschema

    schema = json.loads(SCHEMA_PATH.read_text())
    validator = jsonschema.Draft4Validator(schema, format_checker=jsonschema.FormatChecker())
    errors = sorted(validator.iter_errors(doc), key=lambda e: list(e.path))
    assert not errors, [f"{list(e.path)}: {e.message}" for e in errors[:5]]


def sarif(*args: str | Path, cwd: Path = ROOT) -> tuple[int, dict[str, Any]]:
    r = armcli("check", "--format", "sarif", *args, cwd=cwd)
    return r.returncode, json.loads(r.stdout)


def test_schema_file_is_the_official_one() -> None:
    import hashlib

    assert hashlib.sha256(SCHEMA_PATH.read_bytes()).hexdigest() == SCHEMA_SHA256
    assert json.loads(SCHEMA_PATH.read_text())["title"].startswith(
        "Static Analysis Results Format (SARIF) Version 2.1.0"
    )


def test_clean_robot_is_valid_sarif_with_every_rule() -> None:
    code, doc = sarif("urdf/my_robot.urdf")
    assert code == 0
    validate(doc)
    (run,) = doc["runs"]
    rules = run["tool"]["driver"]["rules"]
    assert [r["id"] for r in rules] == list(RULES)
    for r in rules:
        assert r["shortDescription"]["text"] == RULES[r["id"]].title
        assert RULES[r["id"]].hint in r["help"]["text"]
    assert run["results"] == []


def _broken(tmp_path: Path) -> Path:
    """urdf/my_robot.urdf with the hand's mass negative, in a repository-like directory."""
    repo = tmp_path / "repo"
    (repo / "robots").mkdir(parents=True)
    text = (ROOT / "urdf" / "my_robot.urdf").read_text()
    path = repo / "robots" / "arm.urdf"
    path.write_text(text.replace('<mass value="0.3"/>', '<mass value="-0.3"/>', 1))
    return path


def test_results_point_at_repository_relative_lines(tmp_path: Path) -> None:
    path = _broken(tmp_path)
    repo = path.parents[1]
    code, doc = sarif("robots/arm.urdf", cwd=repo)
    assert code == 1
    validate(doc)
    (result,) = doc["runs"][0]["results"]
    assert result["ruleId"] == "mass-nonpositive" and result["level"] == "error"
    assert doc["runs"][0]["tool"]["driver"]["rules"][result["ruleIndex"]]["id"] == result["ruleId"]
    loc = result["locations"][0]["physicalLocation"]
    assert loc["artifactLocation"] == {"uri": "robots/arm.urdf", "uriBaseId": "%SRCROOT%"}
    mass_line = path.read_text().splitlines().index('      <mass value="-0.3"/>') + 1
    assert loc["region"] == {"startLine": mass_line}
    assert "negative mass" in result["message"]["text"]


def test_fingerprints_are_stable_across_runs_and_line_moves(tmp_path: Path) -> None:
    path = _broken(tmp_path)
    repo = path.parents[1]
    _, first = sarif("robots/arm.urdf", cwd=repo)
    _, again = sarif("robots/arm.urdf", cwd=repo)
    assert first == again  # deterministic: no timestamps or absolute paths
    # Three blank lines at the top move every finding down; the alert must stay the same.
    path.write_text(path.read_text().replace("?>\n", "?>\n\n\n\n", 1))
    _, moved = sarif("robots/arm.urdf", cwd=repo)
    (a,), (b,) = first["runs"][0]["results"], moved["runs"][0]["results"]
    assert b["locations"][0]["physicalLocation"]["region"]["startLine"] == (
        a["locations"][0]["physicalLocation"]["region"]["startLine"] + 3
    )
    assert a["partialFingerprints"] == b["partialFingerprints"]


def test_strict_levels_spec_findings_and_remedies(tmp_path: Path) -> None:
    spec = course_gains_spec(tmp_path)  # the course's Kd 5: the explicit loop diverges
    code, doc = sarif(spec.name, "--strict", cwd=tmp_path)
    assert code == 1
    validate(doc)
    results = doc["runs"][0]["results"]
    assert {r["level"] for r in results} == {"error"}
    pd = next(r for r in results if r["ruleId"] == "pd-explicit-unstable")
    # A finding in the URDF built in memory points at the spec field it comes from (the
    # gains), with that line; the message names the field and the generated file's line.
    loc = pd["locations"][0]["physicalLocation"]
    gains_line = spec.read_text().splitlines().index("  gains:") + 1
    assert loc["artifactLocation"]["uri"] == "my_robot.yaml"
    assert loc["region"] == {"startLine": gains_line}
    assert pd["message"]["text"].startswith(
        ("control.gains (my_robot.urdf:", "control.gains (standalone_arm.urdf:")
    )
    # dt, or Kd alone scaled into the stable range (Kp kept), 0.9 inside the bounds
    assert pd["properties"]["fix"] == {"dt": 0.00063, "kp": [50.0, 50.0], "kd": [3.1, 3.1]}
    fingerprints = [r["partialFingerprints"]["armcliFinding/v1"] for r in results]
    assert len(set(fingerprints)) == len(fingerprints)


def test_unusable_file_in_a_directory_is_a_result(tmp_path: Path) -> None:
    shutil.copy(ROOT / "urdf" / "my_robot.urdf", tmp_path / "good.urdf")
    (tmp_path / "empty.urdf").write_text("")
    code, doc = sarif(".", cwd=tmp_path)
    assert code == 1  # one usable file: the worst finding (the unusable file's error) decides
    validate(doc)
    (result,) = doc["runs"][0]["results"]
    assert result["ruleId"] == "input-unusable"
    uri = result["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
    assert uri == "empty.urdf"


@pytest.mark.parametrize("name", ["a b.urdf", "ü.urdf"])
def test_uris_are_encoded(tmp_path: Path, name: str) -> None:
    _broken(tmp_path).rename(tmp_path / "repo" / name)
    _, doc = sarif(name, cwd=tmp_path / "repo")
    validate(doc)
    uri = doc["runs"][0]["results"][0]["locations"][0]["physicalLocation"]["artifactLocation"]
    assert " " not in uri["uri"] and uri["uri"].endswith(".urdf")


def test_files_outside_the_root_get_absolute_file_uris(tmp_path: Path) -> None:
    from armcli.check.sarif import artifact_uri

    inside = tmp_path / "repo" / "robots" / "a b.urdf"
    outside = tmp_path / "elsewhere" / "x.urdf"
    assert artifact_uri(str(inside), tmp_path / "repo") == ("robots/a%20b.urdf", True)
    uri, relative = artifact_uri(str(outside), tmp_path / "repo")
    assert not relative and uri == outside.resolve().as_uri()


def test_hash_in_a_file_name_stays_in_the_uri(tmp_path: Path) -> None:
    """Issue 20: `a#b.urdf` was split at the `#` into file `a` and part `b.urdf`."""
    _broken(tmp_path).rename(tmp_path / "repo" / "a#b.urdf")
    _, doc = sarif("a#b.urdf", cwd=tmp_path / "repo")
    validate(doc)
    location = doc["runs"][0]["results"][0]["locations"][0]["physicalLocation"]
    assert location["artifactLocation"]["uri"] == "a%23b.urdf"  # before: "a"
    assert location["region"]["startLine"] > 0  # before: no line (taken for an in-memory part)
