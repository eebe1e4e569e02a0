"""Messages a newcomer meets in the first hour (issue 31): each says what to do."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from armcli.cli import COMMANDS
from tests.helpers import DEFAULT_SPEC, ROOT, run_main

PICK = ROOT / "specs" / "trajectories" / "pick.yaml"


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_help_states_each_default_once(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_main([command, "--help"], capsys)
    assert code == 0
    flat = " ".join(out.split())  # rich wraps the help text
    # an option's own "(default ...)" text and typer's "[default: ...]" on one option
    assert not re.search(r"\(default [^)]*\)\.?\s*\[default:", flat), flat


def test_output_formats_listed_and_plot_is_png(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    base = ["simulate", DEFAULT_SPEC, "-t", PICK]
    code, _, err = run_main([*base, "-o", tmp_path / "x.txt"], capsys)
    assert code == 2 and ".mcap" in err
    code, _, err = run_main([*base, "--plot", tmp_path / "x.jpg"], capsys)
    assert code == 2 and "x.png" in err and not (tmp_path / "x.jpg").exists()
    code, out, _ = run_main(["view", "--help"], capsys)
    assert ".mcap" in " ".join(out.split())


def test_massless_link_has_a_remedy(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    spec = tmp_path / "m.yaml"
    spec.write_text(DEFAULT_SPEC.read_text().replace("mass: 0.5\n", "mass: 0\n", 1))
    code, _, err = run_main(["build", spec, "-o", tmp_path / "out"], capsys)
    assert code == 2 and "mass: Input should be greater than 0; a massless link" in err
    assert "give its real mass" in err and not (tmp_path / "out").exists()


def test_readme_tune_section_quotes_the_shipped_gains() -> None:
    from armcli.spec.load import load_spec

    gains = load_spec(DEFAULT_SPEC).control.gains
    (kp,), (kd,) = {g.kp for g in gains.values()}, {g.kd for g in gains.values()}
    readme = (ROOT / "README.md").read_text()
    section = readme[readme.index("### `armcli tune") : readme.index("### `armcli ros-package")]
    assert f"kp = {kp:g}, kd = {kd:g}" in " ".join(section.split())


def test_a_base_without_an_arm_gets_no_arm_advice(capsys: pytest.CaptureFixture[str]) -> None:
    """TurtleBot3-like: wheels and a caster, no arm (tests/fixtures/tipover/wheeled_base.urdf)."""
    urdf = ROOT / "tests" / "fixtures" / "tipover" / "wheeled_base.urdf"
    code, out, _ = run_main(["check", urdf, "--format", "json"], capsys)
    assert code == 0
    doc = json.loads(out)
    (margin,) = [f for f in doc["files"][0]["findings"] if f["rule"] == "support-margin"]
    # centre of mass x = (1 kg * -0.01 m + 0.01 kg * -0.1 m) / 1.11 kg = -9.91 mm behind the
    # wheel axle line (the polygon's front edge)
    assert margin["values"]["margin"] == pytest.approx(0.011 / 1.11, rel=1e-9)
    assert "arm" not in margin["hint"]
    code, out, _ = run_main(["check", urdf], capsys)
    assert "end effector" not in out  # a wheel is no tool point


def test_the_demo_trajectory_ends_off_the_joint_stops() -> None:
    """`make demo` simulates pick.yaml: ending on the stops gave stop hits on every run."""
    from armcli.spec.load import load_spec
    from armcli.trajectory.message import load_trajectory

    spec = load_spec(DEFAULT_SPEC)
    limits = {
        n: (j.limit.lower, j.limit.upper)
        for n, j in spec.arm.joints.items()
        if j.limit and j.limit.lower is not None and j.limit.upper is not None
    }
    traj = load_trajectory(PICK, limits)
    for name, q in zip(traj.joint_names, traj.positions[-1], strict=True):
        lower, upper = limits[name]
        assert lower < q < upper, name


def test_build_says_what_check_will_call_an_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = DEFAULT_SPEC.read_text()
    spec = tmp_path / "v.yaml"
    spec.write_text(text.replace("effort: 100, velocity: 100}", "effort: 100, velocity: 0}", 1))
    code, _, err = run_main(["build", spec, "-o", tmp_path / "out"], capsys)
    assert code == 0  # built: the URDF is valid, only physically meaningless
    (line,) = err.strip().splitlines()
    assert line.startswith(f"warning: {spec}:93 arm.joints.arm_base_forearm_joint.limit.velocity")
    assert "velocity limit 0 must be > 0 (check: limit-effort-velocity)" in line
    code, _, err = run_main(["check", spec], capsys)
    assert code == 1  # the same finding, as check's error
    code, _, err = run_main(["build", DEFAULT_SPEC, "-o", tmp_path / "ok"], capsys)
    assert code == 0 and err == ""  # the example has none


def test_export_mjcf_creates_its_directory_as_build_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run_main(["export", "mjcf", DEFAULT_SPEC, "-o", tmp_path / "a/b/r.xml"], capsys)
    assert code == 0, err
    assert sorted(p.name for p in (tmp_path / "a" / "b").iterdir()) == ["r.xml", "scene.xml"]
    (tmp_path / "f").write_text("")  # a file where a directory would go: refused, untouched
    code, _, err = run_main(["export", "mjcf", DEFAULT_SPEC, "-o", tmp_path / "f/r.xml"], capsys)
    assert code == 2 and "is not a directory" in err


def test_everyday_output_fits_80_columns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Every line within COLUMNS=80 (issue 31: `init`'s next line was 142, `render` 154-284,
    check's xacro note 293 columns); names and paths are never cut to get there."""
    monkeypatch.setenv("COLUMNS", "80")
    monkeypatch.chdir(tmp_path)
    urdf = ROOT / "tests" / "fixtures" / "tipover" / "wheeled_base.urdf"
    runs: list[list[object]] = [
        ["init", "a_project_directory_with_a_long_name"],
        ["build", DEFAULT_SPEC, "-o", "urdf"],
        ["check", DEFAULT_SPEC],
        ["check", urdf],
        ["render", DEFAULT_SPEC, "-o", "robot.png"],
        ["tree", DEFAULT_SPEC],
        ["ros-package", DEFAULT_SPEC, "-o", "ros", "--samples", "20"],
        ["import", urdf, "-o", "imported.yaml"],
        ["export", "mjcf", DEFAULT_SPEC, "--whole-robot", "-o", "mjcf/robot.xml"],  # was 81-130
        ["plan", DEFAULT_SPEC, "--to", "1.5708,0"],  # its note on the snapped limit
    ]
    for args in runs:
        code, out, err = run_main(args, capsys)
        assert code == 0, (args, err)
        long = [line for line in (out + err).splitlines() if len(line) > 80]
        assert not long, (args, long)
    code, out, _ = run_main(["init", "b"], capsys)
    assert "\n  armcli simulate --trajectory trajectories/pick.yaml\n" in out  # whole, to copy


def test_names_get_a_did_you_mean(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_main(
        ["render", DEFAULT_SPEC, "--pose", "foldd", "-o", tmp_path / "x.png"], capsys
    )
    assert code == 2 and "unknown pose 'foldd'; did you mean 'folded'?" in err
    args = ["check", DEFAULT_SPEC, "--payload", "1", "--payload-link", "hand_lnk"]
    code, _, err = run_main(args, capsys)
    assert code == 2 and "did you mean 'hand_link'?" in err
    spec = tmp_path / "p.yaml"
    spec.write_text(
        DEFAULT_SPEC.read_text().replace(
            "home: {arm_base_forearm_joint: 0", "home: {arm_base_forearm_jont: 0"
        )
    )
    code, _, err = run_main(["check", spec], capsys)
    assert code == 2 and "unknown arm joint; did you mean 'arm_base_forearm_joint'?" in err


def test_errors_wrap_at_a_terminal_and_continuations_keep_their_indent(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """An error line (up to 237 columns before) fits COLUMNS, its path whole; check's
    indented stability lines wrap under their own indent (they lost it before)."""
    monkeypatch.setenv("COLUMNS", "60")
    path = "/nonexistent/" + "d" * 70 + "/trajectory.yaml"
    code, _, err = run_main(["simulate", DEFAULT_SPEC, "--trajectory", path], capsys)
    assert code == 2
    lines = err.splitlines()
    assert lines[0].startswith("error: ") and path in lines[0]  # a path is never cut
    assert all(len(line) <= 60 for line in lines[1:]) and all(
        line.startswith("  ") for line in lines[1:]
    )
    code, out, _ = run_main(["check", DEFAULT_SPEC], capsys)
    lines = out.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("  armcli simulate (damping"))
    assert lines[k + 1].startswith("    ")  # its continuation, under its own indent
    assert not any(line.endswith(" ") for line in lines)
