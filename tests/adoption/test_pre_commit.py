"""The published pre-commit hooks (.pre-commit-hooks.yaml) used the way another repository
uses them, with the real pre-commit: it installs armcli into its own virtualenv from this
checkout and runs the hook on a broken and a clean URDF.

`pre-commit try-repo` always installs into a throwaway store (pre_commit/commands/
try_repo.py: `Store(tempdir)`), which takes 1-3 minutes on the shared 2-core machine. So
try-repo is run once (the failing case); the passing case and `armcli-build-check` use
one persistent store through the equivalent `repo:`/`rev:` configuration, which is what
try-repo builds internally and what a consumer repository writes.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from functools import cache
from pathlib import Path

import pytest
import yaml

from tests.helpers import ROOT
from tests.install_helpers import wheelhouse

pytestmark = pytest.mark.slow
INSTALL_TIMEOUT = 900  # [s] pre-commit creates a virtualenv and pip-installs armcli
GIT = ("git", "-c", "user.name=armcli tests", "-c", "user.email=tests@armcli.invalid")


def git(*args: str, cwd: Path) -> str:
    r = subprocess.run([*GIT, *args], cwd=cwd, capture_output=True, text=True, check=True)
    return r.stdout.strip()


@cache
def hook_install_env() -> dict[str, str]:
    """pip's settings for pre-commit's `pip install` of armcli: no engine compile, offline."""
    return {
        "SKBUILD_WHEEL_CMAKE": "false",
        "PIP_NO_INDEX": "1",
        "PIP_FIND_LINKS": str(wheelhouse()),
    }


def pre_commit(*args: str, cwd: Path, home: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PRE_COMMIT_HOME": str(home), "PRE_COMMIT_COLOR": "never"}
    env.update(hook_install_env())
    env.pop("ARMCLI_DEBUG", None)
    return subprocess.run(
        [sys.executable, "-m", "pre_commit", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=INSTALL_TIMEOUT,
    )


def commit_all(repo: Path) -> str:
    git("add", "-A", cwd=repo)
    git("commit", "-q", "-m", "snapshot", cwd=repo)
    return git("rev-parse", "HEAD", cwd=repo)


@pytest.fixture(scope="module")
def hooks_repo(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, str]:
    """A commit of this working tree (tracked and new files, as they are now) in a new repo."""
    pytest.importorskip("pre_commit")
    repo = tmp_path_factory.mktemp("armcli-hooks")
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
    ).stdout.split(b"\0")
    for name in filter(None, (n.decode() for n in listed)):
        src = ROOT / name
        if src.is_file():
            (repo / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, repo / name)
    git("init", "-q", cwd=repo)
    return repo, commit_all(repo)


def consumer(tmp_path: Path) -> Path:
    """Another project's repository with one broken and one clean URDF."""
    repo = tmp_path / "consumer"
    repo.mkdir()
    text = (ROOT / "urdf" / "my_robot.urdf").read_text()
    (repo / "clean.urdf").write_text(text)
    (repo / "broken.urdf").write_text(text.replace('<mass value="0.3"/>', '<mass value="-0.3"/>'))
    git("init", "-q", cwd=repo)
    commit_all(repo)
    return repo


def test_hooks_file_follows_the_conventions() -> None:
    hooks = {h["id"]: h for h in yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())}
    assert set(hooks) == {"armcli-check", "armcli-build-check"}
    for h in hooks.values():
        assert h["language"] == "python" and h["entry"].startswith("armcli ")
        assert {"id", "name", "entry", "files"} <= set(h)
    assert hooks["armcli-build-check"]["pass_filenames"] is False
    assert hooks["armcli-build-check"]["entry"] == "armcli build --check"


def test_try_repo_fails_on_a_broken_urdf(hooks_repo: tuple[Path, str], tmp_path: Path) -> None:
    repo, rev = hooks_repo
    r = pre_commit(
        "try-repo",
        str(repo),
        "armcli-check",
        "--ref",
        rev,
        "--files",
        "broken.urdf",
        cwd=consumer(tmp_path),
        home=tmp_path / "home",
    )
    assert r.returncode == 1, r.stdout + r.stderr
    assert "armcli check (URDF physical sanity)" in r.stdout and "Failed" in r.stdout
    assert "mass-nonpositive" in r.stdout and "negative mass -0.3 kg" in r.stdout


def test_hooks_by_repo_and_rev(hooks_repo: tuple[Path, str], tmp_path: Path) -> None:
    """Clean URDF passes, broken fails; build-check passes on fresh files, fails when stale."""
    repo, rev = hooks_repo
    home = tmp_path / "home"  # one store: the environment is installed once
    config = {
        "repos": [
            {
                "repo": str(repo),
                "rev": rev,
                "hooks": [{"id": "armcli-check"}, {"id": "armcli-build-check"}],
            }
        ]
    }
    user = consumer(tmp_path)
    (user / ".pre-commit-config.yaml").write_text(yaml.safe_dump(config))
    git("add", ".pre-commit-config.yaml", cwd=user)
    r = pre_commit("run", "armcli-check", "--files", "clean.urdf", cwd=user, home=home)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "Passed" in r.stdout
    r = pre_commit("run", "armcli-check", "--files", "broken.urdf", cwd=user, home=home)
    assert r.returncode == 1 and "mass-nonpositive" in r.stdout

    # armcli-build-check in a project that commits a spec and its generated files.
    project = tmp_path / "project"
    for d in ("specs", "urdf"):
        shutil.copytree(ROOT / d, project / d)
    (project / ".pre-commit-config.yaml").write_text(yaml.safe_dump(config))
    git("init", "-q", cwd=project)
    commit_all(project)
    r = pre_commit("run", "armcli-build-check", "--all-files", cwd=project, home=home)
    assert r.returncode == 0, r.stdout + r.stderr
    spec = project / "specs" / "my_robot.yaml"
    text = spec.read_text()
    assert "mass: 0.3" in text
    spec.write_text(text.replace("mass: 0.3", "mass: 0.35", 1))  # generated files now stale
    r = pre_commit("run", "armcli-build-check", "--all-files", cwd=project, home=home)
    assert r.returncode == 1 and "stale" in r.stdout, r.stdout
