"""`armcli init`: the shipped examples, written all-or-nothing, usable as written."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from armcli.cli import main
from armcli.errors import InputError
from armcli.spec.scaffold import TEMPLATES, init_project, template_files
from tests.helpers import ROOT

EXAMPLES = ROOT / "src" / "armcli" / "examples"


def _main(args: list[str]) -> int:
    try:
        main(args)
    except SystemExit as exc:
        return int(exc.code or 0)
    return 0


def test_specs_dir_is_the_package_examples() -> None:
    # one copy: the repository's specs/ is the package's examples/, not a second tree
    assert (ROOT / "specs").resolve() == EXAMPLES.resolve()


@pytest.mark.parametrize("template", sorted(TEMPLATES))
def test_template_files_are_the_examples(template: str) -> None:
    t = TEMPLATES[template]
    files = template_files(template)
    assert files["armcli.yaml"] == (EXAMPLES / t.spec).read_bytes()
    trajectories = sorted((EXAMPLES / t.trajectories).glob("*.yaml"))
    assert trajectories, "a template without trajectories"
    for f in trajectories:
        assert files[f"trajectories/{f.name}"] == f.read_bytes()
    extras = sorted((EXAMPLES / t.extras).iterdir()) if t.extras else []
    for f in extras:  # beside the spec: a world, a Foxglove layout
        assert files[f.name] == f.read_bytes()
    assert set(files) == {"armcli.yaml", "README.md"} | {
        f"trajectories/{f.name}" for f in trajectories
    } | {f.name for f in extras}


@pytest.mark.parametrize("template", sorted(TEMPLATES))
def test_template_is_consistent(template: str) -> None:
    t = TEMPLATES[template]
    spec = yaml.safe_load((EXAMPLES / t.spec).read_text())
    assert spec["name"] == Path(t.spec).stem  # the README's title
    assert t.pose in spec["poses"]  # the README's render command
    arm_joints = set(spec["arm"]["joints"])
    for f in (EXAMPLES / t.trajectories).glob("*.yaml"):
        data = yaml.safe_load(f.read_text())
        if "commands" in data:  # /cmd_vel commands (simulate --cmd-vel): a spec with a drive
            assert spec["mobile_base"]["diff_drive"], f.name
            continue
        assert set(data["joint_names"]) <= arm_joints, f.name


# The course's standalone arm (root arm_base_link, 0.5 kg) hangs from a massless `world`
# link, so it too checks clean: no root-inertia (issue 23).
@pytest.mark.parametrize("template", sorted(TEMPLATES))
def test_a_new_project_checks_clean_under_strict(
    template: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.chdir(tmp_path)
    assert _main(["init", "--template", template]) == 0
    capsys.readouterr()
    code = _main(["check", "--strict"])
    out = capsys.readouterr().out
    assert code == 0 and "no findings" in out, out


def test_init_here_then_every_command_finds_the_spec(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert _main(["init", "--template", "tabletop"]) == 0
    assert capsys.readouterr().out.startswith("wrote 5 files into ./\n")
    for name in ("pick", "wave", "home"):  # the README's command, for each trajectory
        assert _main(["simulate", "--trajectory", f"trajectories/{name}.yaml"]) == 0
        out = capsys.readouterr().out
        assert all(j in out for j in ("yaw_joint", "shoulder_joint", "elbow_joint"))
    assert _main(["tree"]) == 0
    assert "elbow_joint" in capsys.readouterr().out


def test_init_creates_the_directory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "a" / "new"
    assert _main(["init", str(target)]) == 0
    assert (target / "armcli.yaml").is_file() and (target / "trajectories" / "pick.yaml").is_file()
    assert f"\n  cd {target}\n  armcli build\n" in capsys.readouterr().out
    assert sorted(p.name for p in target.parent.iterdir()) == ["new"]  # no staging left


def test_init_refuses_to_overwrite_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "trajectories").mkdir()
    (tmp_path / "trajectories" / "wave.yaml").write_text("mine\n")
    assert _main(["init", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    where = tmp_path / "trajectories" / "wave.yaml"
    assert err == f"error: {where}: already exists; nothing was written (never overwritten)\n"
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == [
        "trajectories",
        "trajectories/wave.yaml",
    ]
    assert (tmp_path / "trajectories" / "wave.yaml").read_text() == "mine\n"


def test_init_into_a_file_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "f").write_text("")
    assert _main(["init", str(tmp_path / "f")]) == 2
    assert capsys.readouterr().err == f"error: {tmp_path}/f: exists and is not a directory\n"


def test_unknown_template(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert _main(["init", str(tmp_path), "--template", "ur5"]) == 2  # a usage error
    assert "'ur5' is not one of 'course', 'rover', 'tabletop'" in capsys.readouterr().err
    with pytest.raises(InputError, match="unknown template 'ur5'; known: course, rover, tabletop"):
        init_project(tmp_path, "ur5")  # the library call says the same
    assert list(tmp_path.iterdir()) == []
