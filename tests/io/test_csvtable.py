"""Bounded numeric CSV (armcli.io.csvtable), the reader behind `view --replay` (issue 20).

A 198 MB replay CSV of 2 rows of 99 million cells peaked at 2.6 GB before it was refused:
the csv module builds a whole row first. The bounds now apply before anything is
allocated: a child process reads each hostile file and its peak memory is measured.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from armcli.errors import InputError
from armcli.io.csvtable import CsvBounds, read_numeric_csv
from armcli.sim.states import load_replay
from tests.helpers import ROOT

WIDE_BYTES = 40_000_000  # a 40 MB hostile file is enough to see a row being built
GROWTH_LIMIT_KB = 30_000  # over reading a 2-row file; before: ~0.4 GB for a 40 MB row
SMALL = CsvBounds(max_bytes=10_000, max_columns=4, max_rows=5, max_cells=12)


def _peak_of_load(path: Path) -> tuple[int, str]:
    """(peak RSS [KiB], error line) of a fresh interpreter running load_replay on `path`."""
    code = (
        "import sys\nfrom armcli.errors import InputError\n"
        "from armcli.sim.states import load_replay\n"
        f"try:\n    load_replay({str(path)!r}, ['j'])\nexcept InputError as e:\n"
        "    sys.stderr.write(str(e))\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code], cwd=ROOT, stderr=subprocess.PIPE, text=True
    )
    assert proc.stderr is not None
    said = proc.stderr.read()
    proc.stderr.close()
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_maxrss, said


@pytest.mark.parametrize("shape", ["wide-row", "wide-header"])
def test_wide_file_is_refused_before_allocating(shape: str, tmp_path: Path) -> None:
    path = tmp_path / "huge.csv"
    cells = WIDE_BYTES // 2
    with path.open("w") as fh:
        if shape == "wide-row":
            fh.write("time,j.position\n0")
        else:
            fh.write("time")
        for _ in range(cells // 1_000_000):
            fh.write(",1" * 1_000_000)
        fh.write("\n")
    small = tmp_path / "small.csv"
    small.write_text("time,j.position\n0,1\n0.1,2\n")
    baseline, said = _peak_of_load(small)  # the interpreter and imports
    assert said == ""
    peak, said = _peak_of_load(path)
    line = 2 if shape == "wide-row" else 1
    assert f"huge.csv:{line}: " in said and "longer than" in said, said
    assert peak - baseline < GROWTH_LIMIT_KB, (peak, baseline)  # before: the row was built


def test_cells_rows_and_columns_are_bounded(tmp_path: Path) -> None:
    path = tmp_path / "t.csv"
    path.write_text("a,b,c,d,e\n")
    with pytest.raises(InputError, match=r"t\.csv:1: 5 columns, at most 4"):
        read_numeric_csv(path, SMALL, lambda _: False)
    path.write_text("a,b,c\n" + "1,2,3\n" * 5)  # 15 cells > 12
    with pytest.raises(InputError, match=r"t\.csv:6: more than 4 data rows \(12 cells at most\)"):
        read_numeric_csv(path, SMALL, lambda _: False)
    path.write_text("a\n" + "1\n" * 6)
    with pytest.raises(InputError, match=r"t\.csv:7: more than 5 data rows"):
        read_numeric_csv(path, SMALL, lambda _: False)
    path.write_text("a,b\n1," + "2" * 200 + "\n")
    with pytest.raises(InputError, match=r"t\.csv:2: line of 2 cells longer than 130 characters"):
        read_numeric_csv(path, SMALL, lambda _: False)


def test_values_blank_lines_and_line_numbers(tmp_path: Path) -> None:
    path = tmp_path / "t.csv"
    path.write_text("a, b\r\n1,\r\n\r\n2.5,nan\r\n")
    table = read_numeric_csv(path, SMALL, lambda h: h == "b")
    assert table.header == ("a", "b")
    assert table.values[:, 0].tolist() == [1.0, 2.5] and np.isnan(table.values[:, 1]).all()
    assert table.lines.tolist() == [2, 4]
    path.write_text("a,b\n1,2\n\nx,3\n")
    with pytest.raises(InputError, match=r"t\.csv:4 a: expected a finite number, got 'x'"):
        read_numeric_csv(path, SMALL, lambda _: False)


def test_duplicate_joint_columns_are_refused(tmp_path: Path) -> None:
    """Issue 20: `view --replay` took the second `j.position` column and ignored the first."""
    path = tmp_path / "states.csv"
    path.write_text("time,j.position,j.position\n0,1,2\n0.1,1,2\n")
    with pytest.raises(InputError, match=r"states\.csv:1: column 'j\.position' appears twice"):
        load_replay(path, ["j"])


def test_time_error_names_the_file_line_past_blank_lines(tmp_path: Path) -> None:
    path = tmp_path / "states.csv"
    path.write_text("time,j.position\n0,1\n\n0.2,1\n0.1,1\n")
    with pytest.raises(InputError, match=r"states\.csv:5 time: time must increase"):
        load_replay(path, ["j"])
    path.write_text("time,j.position\n0,1\n\n0.2,1\n")
    assert math.isclose(load_replay(path, ["j"]).duration, 0.2)
