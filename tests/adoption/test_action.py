"""The GitHub Action (action.yml + action/run.sh) run locally with the environment an
Actions runner gives the step: annotations, SARIF file, outputs, exit codes."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from tests.check.test_sarif import validate
from tests.helpers import ROOT

SCRIPT = ROOT / "action" / "run.sh"
ANNOTATION = re.compile(r"^::(error|warning) file=([^,]+),line=(\d+),title=armcli ([a-z-]+)::")


def consumer_repo(tmp_path: Path) -> Path:
    """Another repository: a clean and a broken URDF under robots/."""
    repo = tmp_path / "consumer"
    (repo / "robots").mkdir(parents=True)
    text = (ROOT / "urdf" / "my_robot.urdf").read_text()
    (repo / "robots" / "clean.urdf").write_text(text)
    (repo / "robots" / "broken.urdf").write_text(
        text.replace('<mass value="0.3"/>', '<mass value="-0.3"/>', 1)
    )
    return repo


Run = tuple[subprocess.CompletedProcess[str], dict[str, str]]


def run_action(repo: Path, **inputs: str) -> Run:
    """bash action/run.sh as the composite step runs it: inputs as INPUT_* variables,
    GITHUB_OUTPUT a file, the working directory the checked-out repository."""
    out = repo / "github_output.txt"
    out.write_text("")
    env = {
        **os.environ,
        "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
        "GITHUB_ACTIONS": "true",
        "GITHUB_OUTPUT": str(out),
        "GITHUB_ACTION_PATH": str(ROOT),
        **{f"INPUT_{k.upper()}": v for k, v in inputs.items()},
    }
    env.pop("ARMCLI_DEBUG", None)
    r = subprocess.run(
        ["bash", str(SCRIPT)], cwd=repo, env=env, capture_output=True, text=True, timeout=300
    )
    outputs = dict(line.split("=", 1) for line in out.read_text().splitlines() if "=" in line)
    return r, outputs


def test_action_yml_passes_every_input_to_the_script() -> None:
    action = yaml.safe_load((ROOT / "action.yml").read_text())
    assert action["runs"]["using"] == "composite"
    step = next(s for s in action["runs"]["steps"] if s.get("id") == "check")
    assert step["run"] == 'bash "$GITHUB_ACTION_PATH/action/run.sh"'
    for name in ("paths", "strict", "sarif-file", "args"):
        assert name in action["inputs"]
        var = "INPUT_" + name.upper().replace("-", "_")
        assert step["env"][var] == "${{ inputs." + name + " }}"  # env only: no ${{ }} in run
        assert var in SCRIPT.read_text()
    assert "${{" not in step["run"]


def test_broken_and_clean_files_annotate_and_write_sarif(tmp_path: Path) -> None:
    repo = consumer_repo(tmp_path)
    r, outputs = run_action(repo, paths="robots", strict="false", sarif_file="reports/armcli.sarif")
    assert r.returncode == 1, r.stderr
    lines = r.stdout.splitlines()
    assert lines and all(ANNOTATION.match(line) for line in lines), lines
    files = {ANNOTATION.match(line).group(2) for line in lines}
    assert files == {"robots/broken.urdf"}  # the clean file has nothing to say
    assert {ANNOTATION.match(line).group(4) for line in lines} == {"mass-nonpositive"}
    assert outputs == {"exit-code": "1", "sarif-file": "reports/armcli.sarif"}
    doc = json.loads((repo / "reports" / "armcli.sarif").read_text())
    validate(doc)
    uris = {
        r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
        for r in doc["runs"][0]["results"]
    }
    assert uris == {"robots/broken.urdf"}


def test_clean_file_passes(tmp_path: Path) -> None:
    repo = consumer_repo(tmp_path)
    r, outputs = run_action(repo, paths="robots/clean.urdf")
    assert r.returncode == 0, r.stderr
    assert r.stdout == "" and outputs["exit-code"] == "0" and outputs["sarif-file"] == ""


def test_strict_and_extra_args(tmp_path: Path) -> None:
    repo = consumer_repo(tmp_path)
    # the standalone arm without its massless `world` root: a root-inertia warning
    text = (ROOT / "urdf" / "standalone_arm.urdf").read_text()
    text, n = re.subn(
        r'  <link name="world"/>\n  <joint name="world_joint".*?</joint>\n', "", text, flags=re.S
    )
    assert n == 1
    (repo / "arm.urdf").write_text(text)
    r, _ = run_action(repo, paths="arm.urdf", strict="true")
    assert r.returncode == 1 and r.stdout.startswith("::error file=arm.urdf,")
    r, _ = run_action(repo, paths="arm.urdf", strict="true", args="--ignore root-inertia")
    assert r.returncode == 0, r.stdout


@pytest.mark.parametrize(
    ("inputs", "message"),
    [
        ({"paths": "robots", "strict": "maybe"}, "input 'strict' must be true or false"),
        ({"paths": "no_such_dir"}, "URDF file not found"),
    ],
)
def test_bad_inputs_exit_2(tmp_path: Path, inputs: dict[str, str], message: str) -> None:
    r, _ = run_action(consumer_repo(tmp_path), **inputs)
    assert r.returncode == 2
    assert message in r.stdout + r.stderr


def test_shell_metacharacters_in_paths_are_not_run(tmp_path: Path) -> None:
    repo = consumer_repo(tmp_path)
    marker = tmp_path / "pwned"
    r, _ = run_action(repo, paths=f"robots/clean.urdf;touch${{IFS}}{marker}", args="$(touch x)")
    assert r.returncode == 2  # no such file / unknown option, not a shell command
    assert not marker.exists() and not (repo / "x").exists()


def test_input_values_cannot_inject_workflow_commands(tmp_path: Path) -> None:
    """Issue 20: the action's own error line printed the input raw."""
    r, _ = run_action(consumer_repo(tmp_path), strict="no\n::add-mask::armcli\r::x::y")
    assert r.returncode == 2
    lines = [ln.strip() for ln in re.split(r"\r\n|\r|\n", r.stdout + r.stderr)]
    assert [ln for ln in lines if ln.startswith("::")] == [
        "::error title=armcli action::input 'strict' must be true or false, "
        "got 'no%0A::add-mask::armcli%0D::x::y'"
    ]
