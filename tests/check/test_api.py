"""`check` as one library call: options refused by field, the verdict as an error to raise."""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.check.api import check
from armcli.check.options import CheckOptions, TipoverOptions
from armcli.errors import EXIT_FAILED, EXIT_OK, FindingsError, InputError
from tests.helpers import ROOT

GOOD = ROOT / "urdf" / "my_robot.urdf"


def test_options_are_refused_by_their_field_before_any_file_is_read(tmp_path: Path) -> None:
    missing = tmp_path / "nowhere.urdf"  # never read: the options are refused first
    with pytest.raises(InputError) as err:
        check([missing], CheckOptions(), ignore=["no-such-rule"])
    assert err.value.field == "ignore"
    with pytest.raises(InputError) as err:
        check([missing], CheckOptions(tipover=TipoverOptions(payload=-1.0)))
    assert err.value.field == "TipoverOptions.payload" and "--" not in str(err.value)


def test_the_verdict_is_the_error_the_run_ends_with(tmp_path: Path) -> None:
    ok = check([GOOD], CheckOptions())
    assert ok.code == EXIT_OK and ok.error() is None
    broken = tmp_path / "zero_axis.urdf"
    broken.write_text(GOOD.read_text().replace('<axis xyz="0 1 0"/>', '<axis xyz="0 0 0"/>', 1))
    bad = check([broken], CheckOptions())
    assert bad.code == EXIT_FAILED and "axis" in {f.rule for f in bad.findings}
    assert isinstance(bad.error(), FindingsError)
    assert check([broken], CheckOptions(), ignore=["axis"]).error() is None  # as --ignore
