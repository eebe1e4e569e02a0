"""The command-line shell: lazy command table, --version, python -m armcli, error labels."""

from __future__ import annotations

import subprocess
import sys

import pytest

from armcli.cli import COMMANDS, load_command


@pytest.mark.parametrize("name", list(COMMANDS))
def test_command_table_help_is_the_commands_docstring(name: str) -> None:
    """The list in `armcli --help` comes from COMMANDS; it must say what the command says."""
    command = load_command(name)
    assert command.name == name
    assert COMMANDS[name][1] == (command.help or "").strip().splitlines()[0]


def test_help_imports_no_command_module() -> None:
    """`armcli --help` stays instant: no command, pydantic or numpy import."""
    code = (
        "import sys\nfrom armcli.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "heavy = ('armcli.commands.', 'pydantic', 'numpy')\n"
        "print('LOADED:' + ','.join(sorted(m for m in sys.modules if m.startswith(heavy))))"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "Commands:" in res.stdout
    assert res.stdout.strip().splitlines()[-1] == "LOADED:"


HEAVY = ("numpy", "pinocchio", "lxml", "mujoco", "yourdfpy", "matplotlib", "trimesh", "scipy")


def test_command_help_imports_nothing_heavy() -> None:
    """`armcli CMD --help` builds every command's help from typer and help text alone.

    One interpreter per command (a module one command loads would hide another's), all
    started together: ~0.1 s each.
    """
    code = (
        "import sys\nfrom armcli.cli import main\n"
        "try:\n    main(sys.argv[1:])\nexcept SystemExit as e:\n    assert e.code in (0, None), e\n"
        f"heavy = {HEAVY!r}\n"
        "print('LOADED:' + ','.join(sorted(m for m in sys.modules if m.split('.')[0] in heavy)))"
    )
    argvs = [[name, "--help"] for name in COMMANDS] + [["export", "mjcf", "--help"]]
    procs = {
        " ".join(argv): subprocess.Popen(
            [sys.executable, "-c", code, *argv],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for argv in argvs
    }
    loaded = {}
    for cmd, proc in procs.items():
        out, err = proc.communicate(timeout=60)
        assert proc.returncode == 0, (cmd, err)
        assert "Usage:" in out, cmd
        loaded[cmd] = out.strip().splitlines()[-1]
    assert loaded == {cmd: "LOADED:" for cmd in procs}


def test_version_and_module_entry_point() -> None:
    from importlib.metadata import version

    res = subprocess.run(
        [sys.executable, "-m", "armcli", "--version"], capture_output=True, text=True, check=False
    )
    assert res.returncode == 0
    assert res.stdout.startswith(f"armcli {version('armcli')} (")  # then engine, pin, xacro


def test_unknown_command_is_a_usage_error() -> None:
    res = subprocess.run(
        [sys.executable, "-m", "armcli", "no-such-command"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert res.returncode == 2 and "No such command" in res.stderr


@pytest.mark.parametrize(
    ("args", "reason"),
    [
        (["plan", "--timeout", "abc", "--format", "json"], "Invalid value for '--timeout'"),
        (["check", "--no-such-option", "--format=json"], "No such option: --no-such-option"),
        (["no-such-command", "--format", "json"], "No such command 'no-such-command'"),
    ],
)
def test_a_usage_error_is_json_on_stdout_too(
    args: list[str], reason: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 40: --format json got an empty stdout when click refused an option's value."""
    import json

    from tests.helpers import run_main

    code, out, err = run_main(args, capsys)
    assert code == 2 and reason in err
    doc = json.loads(out)
    assert doc["status"] == "error" and doc["exit_code"] == 2 and reason in doc["reason"]


def test_a_bad_option_value_names_no_environment_variable(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """click 8.2.1 printed "Invalid value for '--dt' (env var: 'None')" (click issue #2971)."""
    from tests.helpers import run_main

    code, _, err = run_main(["simulate", "--dt", "abc"], capsys)
    assert code == 2 and "Invalid value for '--dt': 'abc'" in err and "env var" not in err


@pytest.mark.parametrize("name", list(COMMANDS))
def test_no_help_states_a_default_the_option_lacks(name: str) -> None:
    """`place --help` said "--target ... (default: Ellipsis)" for a required option."""
    import click

    helps = [p.help or "" for p in load_command(name).params if isinstance(p, click.Option)]
    assert not [h for h in helps if "Ellipsis" in h or "(default: None)" in h]
