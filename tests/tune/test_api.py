"""`tune` as one library call: outputs refused before any rollout, the files as bytes."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from armcli.errors import InputError
from armcli.tune import job as tjob
from armcli.tune.api import TuneRequest, tune
from armcli.tune.search import SearchOptions
from tests.helpers import ROOT

SPEC = ROOT / "specs" / "my_robot.yaml"
QUICK = tjob.TuneSettings(settle=0.3)  # short settle windows keep the test quick
TRIALS = 4


def test_an_unwritable_output_is_refused_before_the_job_is_prepared(tmp_path: Path) -> None:
    calls: list[str] = []
    req = TuneRequest(SPEC, QUICK, SearchOptions(trials=TRIALS), output=tmp_path / "gains.txt")
    with pytest.raises(InputError) as err:
        tune(req, started=lambda job, engine: calls.append(engine))
    assert err.value.field == "output" and "--" not in str(err.value)  # the CLI adds its flag
    assert calls == []  # nothing prepared, nothing searched


def test_the_files_come_back_as_bytes_and_nothing_is_written(tmp_path: Path) -> None:
    heard: list[Any] = []
    out = tmp_path / "gains.json"
    req = TuneRequest(
        SPEC, QUICK, SearchOptions(trials=TRIALS, batch=2), jobs=1, output=out, write=False
    )
    tuned = tune(
        req,
        started=lambda job, engine: heard.append(engine),
        progress=lambda done, total: heard.append((done, total)),
    )
    assert heard[0] == tuned.engine  # the start is told before the first batch
    assert heard[1:] and all(total == TRIALS for _, total in heard[1:])
    assert list(tuned.files) == [out] and not out.exists()  # the caller writes them
    data = json.loads(tuned.files[out])
    assert data["search"]["engine"] == tuned.engine and data["search"]["trials"] == TRIALS
    assert set(data["results"]) == {r.label for r in tuned.outcome.rows} >= {"tuned"}
