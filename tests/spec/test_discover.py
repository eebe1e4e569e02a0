"""Which spec a command uses without an argument: ./armcli.yaml, then specs/*.yaml."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from armcli.cli import main
from armcli.errors import NoSpecError
from armcli.spec.discover import find_spec
from tests.helpers import ROOT

SPEC = ROOT / "specs" / "my_robot.yaml"


@pytest.fixture(autouse=True)
def _cwd(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)


def _put(rel: str) -> Path:
    path = Path(rel)
    path.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(SPEC, path)
    return path


def test_an_argument_wins() -> None:
    _put("armcli.yaml")
    assert find_spec(Path("other.yaml")) == Path("other.yaml")


def test_armcli_yaml_before_specs_dir() -> None:
    _put("armcli.yaml")
    _put("specs/only.yaml")
    assert find_spec(None) == Path("armcli.yaml")  # relative: labels stay as the user sees them


def test_the_only_spec_in_specs() -> None:
    _put("specs/only.yaml")
    assert find_spec(None) == Path("specs/only.yaml")


def test_the_default_name_among_several() -> None:
    _put("specs/a.yaml")
    _put("specs/my_robot.yaml")
    assert find_spec(None) == Path("specs/my_robot.yaml")


def test_several_without_the_default_name_are_listed() -> None:
    _put("specs/a.yaml")
    _put("specs/b.yaml")
    with pytest.raises(NoSpecError, match=r"several in specs/ \(specs/a.yaml, specs/b.yaml\)"):
        find_spec(None)


def test_nothing_here_says_to_run_init() -> None:
    with pytest.raises(NoSpecError, match=r"run `armcli init`"):
        find_spec(None)


@pytest.mark.parametrize(
    "command",
    ["build", "check", "simulate", "tune", "ros-package", "render", "tree", "export mjcf"],
)
def test_commands_say_to_run_init(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        main(command.split())
    err = capsys.readouterr().err
    assert info.value.code == 2
    assert err.count("\n") == 1 and "no ./armcli.yaml or specs/*.yaml here" in err
    assert "`armcli init`" in err
    assert list(Path().iterdir()) == []  # nothing written


def test_build_finds_armcli_yaml(capsys: pytest.CaptureFixture[str]) -> None:
    _put("armcli.yaml")
    with pytest.raises(SystemExit) as info:
        main(["build"])
    assert info.value.code == 0
    assert capsys.readouterr().out.startswith("built 9 files from armcli.yaml into urdf/")
    # generated files name the spec as found, relative to the cwd
    assert "armcli.yaml" in Path("urdf/my_robot.urdf.xacro").read_text()
