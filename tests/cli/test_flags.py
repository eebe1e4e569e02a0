"""Library errors name what a Python caller passed; the commands turn those into flags."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from armcli.cli import main
from armcli.commands.flags import flag_errors, option_flags
from armcli.errors import InputError, Problem, SpecError
from armcli.sim import job as simjob
from armcli.sim.options import SimOptions
from armcli.sim.simulate import SimConfig
from armcli.spec.load import load_spec
from armcli.urdf.source import RobotFile
from tests.helpers import DEFAULT_SPEC, ROOT

LIBRARY = ROOT / "src" / "armcli"
FLAG_FIELD = re.compile(r"""field(?:: str)?\s*=\s*f?["']--""")  # a keyword or a default
# Still naming flags: parsers of CLI-format values (NAME=PATH, VAR=VALUE) and the --env
# values they produce (urdf/source.py); a library caller passes dicts instead.
LEFT = {"io/packages.py", "xacro/args.py", "urdf/source.py"}
MESSAGE = "joint_names: [arm_base_forearm_joint]\npoints: [{positions: [0.1]}]"


def test_library_code_names_no_flags() -> None:
    naming = {
        p.relative_to(LIBRARY).as_posix()
        for p in LIBRARY.rglob("*.py")
        if p.parent.name != "commands" and p.name != "cli.py" and FLAG_FIELD.search(p.read_text())
    }
    assert naming == LEFT


def test_a_python_caller_is_told_the_option_it_passed() -> None:
    spec = load_spec(DEFAULT_SPEC)
    with pytest.raises(InputError) as err:
        simjob.prepare(RobotFile.of_spec(spec), SimOptions(message=MESSAGE, dt=0.5))
    assert err.value.field == "SimOptions.dt" and "--" not in str(err.value)
    with pytest.raises(InputError) as err:
        simjob.prepare(RobotFile.of_spec(spec), SimOptions(message=MESSAGE, kp=(1.0, 2.0, 3.0)))
    assert err.value.field == "SimOptions.kp"


def test_the_cli_is_told_the_flag(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        main(["simulate", str(DEFAULT_SPEC), "-m", MESSAGE, "--duration", "1e9"])
    assert exit_.value.code == 2
    assert capsys.readouterr().err == "error: --duration: must be in (0, 3600] s, got 1e+09\n"


def test_rename_covers_field_file_and_quoted_names() -> None:
    names = {"Opts.a": "--a", "Opts.b": "--b"}
    exc = InputError("give `Opts.a` or `Opts.b`, not `other`", file="Opts.b", field="Opts.a")
    got = exc.renamed(names)
    assert got.message == "give --a or --b, not `other`"
    assert (got.field, got.file, str(got)) == ("--a", "--b", "--b --a: " + got.message)
    assert exc.renamed({}) is exc  # nothing to rename: the same error


def test_rename_keeps_the_class_and_its_lines() -> None:
    exc = SpecError("spec.yaml", [Problem("control.dt", "must be > 0", 3)])
    got = exc.renamed({"spec.yaml": "SPEC"})
    assert type(got) is SpecError and got.lines() == ["SPEC:3 control.dt: must be > 0"]


def test_flag_errors_renames_inside_and_passes_other_errors() -> None:
    with pytest.raises(InputError, match=r"^--x: bad$"), flag_errors({"Opts.x": "--x"}):
        raise InputError("bad", field="Opts.x")
    with pytest.raises(ValueError), flag_errors({"Opts.x": "--x"}):
        raise ValueError("not an armcli error")


def test_option_flags_refuses_an_override_for_a_missing_field() -> None:
    @dataclass
    class Opts:
        some_value: int = 0

    assert option_flags(Opts) == {"Opts.some_value": "--some-value"}
    with pytest.raises(ValueError, match="no field other"):
        option_flags(Opts, other="--other")


@pytest.mark.parametrize(
    ("dt", "yaml"),
    [(0.0, "0"), (-1e-3, "-0.001"), (math.nan, ".nan"), (math.inf, ".inf"), (0.5, "0.5")],
)
def test_one_time_step_rule_names_each_entry(
    dt: float, yaml: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """control.dt, SimOptions.dt (simulate's and drive's --dt) and SimConfig.dt once had three
    rules (> 0; finite and > 0; in (0, 0.1]): now spec/types.py's one, naming the user's field."""
    rule = f"must be finite and in (0, 0.1] s, got {dt:g}"
    spec_file = tmp_path / "robot.yaml"
    spec_file.write_text(DEFAULT_SPEC.read_text().replace("  dt: 0.001", f"  dt: {yaml}"))
    with pytest.raises(SpecError) as spec_err:
        load_spec(spec_file)
    assert spec_err.value.problems[0].field == "control.dt"
    assert spec_err.value.problems[0].message == rule
    spec = load_spec(DEFAULT_SPEC)
    with pytest.raises(InputError) as opt_err:
        simjob.prepare(RobotFile.of_spec(spec), SimOptions(message=MESSAGE, dt=dt))
    assert (opt_err.value.field, opt_err.value.message) == ("SimOptions.dt", rule)
    with pytest.raises(InputError) as cfg_err:
        SimConfig(np.ones(1), np.ones(1), dt=dt)
    assert (cfg_err.value.field, cfg_err.value.message) == ("SimConfig.dt", rule)
    with pytest.raises(SystemExit):
        main(["simulate", str(DEFAULT_SPEC), "-m", MESSAGE, "--dt", str(dt)])
    assert capsys.readouterr().err == f"error: --dt: {rule}\n"
