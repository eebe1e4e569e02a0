"""The CLI as the invoking user (root on CI) and as an ordinary user, in a shared work directory."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.helpers import ROOT
from tests.urdf.ordinary_user import Run, ordinary_user

CLI_TIMEOUT_S = 120.0


@pytest.fixture(params=["invoker", "ordinary-user"])
def run(request: pytest.FixtureRequest) -> Iterator[tuple[Path, Run]]:
    """(a work directory every user can read, a function running the CLI there).

    The function runs `armcli ARGS`, or with `code=` the Python code `code` with ARGS in
    `sys.argv[1:]`, as the user; HOME is the work directory.
    """
    work = Path(tempfile.mkdtemp(prefix="armcli-harden-"))  # pytest's tmp_path is root's
    work.chmod(0o755)
    prefix: tuple[str, ...] = ()
    user = None
    if request.param == "ordinary-user":
        user = ordinary_user()
        if isinstance(user, str):
            pytest.skip(f"cannot run as an ordinary user here: {user}")
        prefix = user.prefix

    def cli(
        *args: str | Path, env: dict[str, str] | None = None, code: str | None = None
    ) -> subprocess.CompletedProcess[str]:
        if user is not None:
            user.own(work)
        base = {"PATH": os.environ["PATH"], "HOME": str(work), "LANG": "C.UTF-8"}
        program = ("-c", code) if code is not None else ("-m", "armcli.cli")
        return subprocess.run(
            [*prefix, sys.executable, *program, *map(str, args)],
            capture_output=True,
            text=True,
            timeout=CLI_TIMEOUT_S,
            check=False,
            cwd=work,
            env={**base, "PYTHONPATH": str(ROOT / "src"), **(env or {})},
        )

    try:
        yield work, cli
    finally:
        shutil.rmtree(work, ignore_errors=True)
