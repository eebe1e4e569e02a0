"""Findings on a spec point at the spec's own line and field; the URDF line stays secondary."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from armcli.check.findings import Finding
from armcli.check.inputs import run_check
from armcli.check.options import CheckOptions
from armcli.check.report import to_github, to_json
from armcli.check.sarif import to_sarif
from tests.helpers import COURSE_GAINS, DEFAULT_SPEC, SPECS, gains_text

# The seed spec with a feather-light forearm, a motor too weak to hold the arm up and the
# course's Kd 5 (which an explicit loop does not hold at 1 ms).
EDITS = (("      mass: 0.3\n", "      mass: 0.00001\n"), ("effort: 100,", "effort: 0.01,"))


@pytest.fixture(scope="module")
def broken(tmp_path_factory: pytest.TempPathFactory) -> Path:
    text = gains_text(DEFAULT_SPEC.read_text(), COURSE_GAINS)
    for old, new in EDITS:
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path_factory.mktemp("spec") / "armcli.yaml"
    path.write_text(text)
    return path


def _findings(path: Path) -> list[Finding]:
    run = run_check([path], CheckOptions())
    return [f for r in run.results for f in r.findings]


def _line_of(path: Path, text: str) -> int:
    """1-based line of the first line containing `text` (found independently of armcli)."""
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


def test_findings_name_the_spec_line_and_field(broken: Path) -> None:
    found = {(f.rule, f.file.partition("#")[2]): f for f in _findings(broken)}
    tiny = found["tiny-mass", "standalone_arm.urdf"]
    assert tiny.spec is not None
    assert (tiny.spec.file, tiny.spec.field) == (str(broken), "arm.links.forearm_link.mass")
    assert tiny.spec.line == _line_of(broken, "mass: 0.00001")
    weak = found["gravity-effort", "my_robot.urdf"]
    assert weak.spec is not None
    assert weak.spec.field == "arm.joints.arm_base_forearm_joint.limit.effort"
    assert weak.spec.line == _line_of(broken, "effort: 0.01")
    gains = found["pd-explicit-unstable", "my_robot.urdf"]
    assert gains.spec is not None and gains.spec.field.startswith("control.gains")
    assert gains.spec.line == _line_of(broken, "gains:")
    # the generated URDF's line is kept: it is the <mass> element of that link there
    assert tiny.line is not None and tiny.line > 0


@pytest.mark.parametrize("spec", sorted(SPECS.glob("*.yaml")), ids=lambda p: p.name)
def test_every_spec_finding_points_at_a_line_holding_its_field(spec: Path) -> None:
    lines = spec.read_text().splitlines()
    for f in _findings(spec):
        assert f.spec is not None, (f.rule, f.message)
        assert f.spec.line is not None
        last = re.split(r"[.\[]", f.spec.field)[-1].rstrip("]")
        assert last in lines[f.spec.line - 1], (f.spec, lines[f.spec.line - 1])


def test_urdf_findings_have_no_spec_place(built_dir: Path) -> None:
    assert all(f.spec is None for f in _findings(built_dir / "my_robot.urdf"))


def test_json_sarif_and_github_carry_the_spec_place(broken: Path) -> None:
    run = run_check([broken], CheckOptions())
    findings = [f for r in run.results for f in r.findings]
    doc = json.loads(to_json(run.results, findings, 1))
    spec_places = [x["spec"] for file in doc["files"] for x in file["findings"]]
    assert all(p["file"] == str(broken) and p["line"] and p["field"] for p in spec_places)
    sarif = json.loads(to_sarif(findings))
    line = _line_of(broken, "effort: 0.01")
    regions = [
        r["locations"][0]["physicalLocation"].get("region", {}).get("startLine")
        for r in sarif["runs"][0]["results"]
        if r["ruleId"] == "gravity-effort"
    ]
    assert regions and set(regions) == {line}
    github = to_github(findings)
    assert f"line={line},title=armcli gravity-effort::arm.joints.arm_base_forearm_joint" in github
    assert "(my_robot.urdf:" in github  # the generated file's line, as secondary information
