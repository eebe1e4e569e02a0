"""Every table at 80 and 200 columns: no ellipsis, lines that fit, every number whole.

The numbers come from the library's own results (check's JSON document, tune's JSON
output, the simulation's metrics), formatted as the tables print them, and must appear
as whole words in the command's output. Into a pipe (no COLUMNS), nothing is wrapped.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from tests.helpers import ROOT, run_main, spec_file

SPEC = ROOT / "specs" / "my_robot.yaml"
PICK = ROOT / "specs" / "trajectories" / "pick.yaml"
WIDTHS = (80, 200)
QUICK_TUNE = ["--trials", "4", "--batch", "2", "--settle", "0.5", "-t", str(PICK), "-j", "1"]


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code, out, _ = run_main(args, capsys)
    return code, out


def g4(x: float | None) -> str:
    """The tables' general number format (4 significant digits)."""
    return "-" if x is None else f"{x:.4g}"


def assert_fits(out: str, width: int, numbers: list[str]) -> None:
    assert "…" not in out
    too_long = [line for line in out.splitlines() if len(line) > width]
    assert not too_long, too_long
    words = set(out.split())
    missing = [n for n in numbers if n not in words]
    assert not missing, (missing, out)


@pytest.mark.parametrize("width", WIDTHS)
def test_check_tables_fit(
    width: int, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("COLUMNS", str(width))
    _, text = run(["check", str(SPEC), "--format", "json"], capsys)
    doc = json.loads(text)
    _, out = run(["check", str(SPEC)], capsys)
    numbers = []
    for f in doc["files"]:
        s = f["summary"]
        for j in s["joints"]:
            keys = ("lower", "upper", "effort", "velocity", "damping", "friction", "gravity_max")
            numbers += [g4(j[k]) for k in keys]
        numbers += [f"{v:.4f}" for p in s["poses"] for v in p["xyz"]]
        for x in f["findings"]:  # spec place first, the generated URDF's line in brackets
            if x["spec"]:
                numbers.append(f"{x['spec']['file']}:{x['spec']['line']}")
                numbers.append(f"({x['file'].partition('#')[2]}:{x['line']})")
    assert_fits(out, width, numbers)


@pytest.mark.parametrize("width", WIDTHS)
def test_simulate_table_fits(
    width: int, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from armcli.sim import job as simjob
    from armcli.sim.options import SimOptions
    from armcli.sim.report import joint_metrics

    monkeypatch.setenv("COLUMNS", str(width))
    _, out = run(["simulate", str(SPEC), "-t", str(PICK)], capsys)
    job = simjob.prepare(spec_file(SPEC), SimOptions(trajectory=PICK))
    res = simjob.run(job)  # the same deterministic run, through the library
    numbers = []
    for m in joint_metrics(res, job.trajectory.duration):
        numbers += [f"{m.rms_error:.4f}", f"{m.max_error:.4f}", f"{m.final_error:+.4f}"]
        numbers += [f"{m.saturated_pct:.1f}", str(m.limit_contacts)]
        numbers.append("not" if m.settle_time is None else f"{m.settle_time:.3f}")
    assert_fits(out, width, numbers)


@pytest.mark.parametrize("width", WIDTHS)
def test_tune_tables_fit(
    width: int,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    tmp_path: Path,
) -> None:
    monkeypatch.setenv("COLUMNS", str(width))
    result = tmp_path / "tune.json"
    code, out = run(["tune", str(SPEC), *QUICK_TUNE, "-o", str(result)], capsys)
    assert code == 0, out
    doc: dict[str, Any] = json.loads(result.read_text())
    numbers = []
    for r in doc["start"]:
        numbers += [g4(r[k]) for k in ("wn", "kp", "kd")]
    for row in doc["results"].values():
        for j in row["joints"].values():
            numbers += [g4(j[k]) for k in ("kp", "kd", "rms", "max", "final", "settle")]
            numbers.append(f"{j['saturated_pct']:.1f}")
            numbers.append(f"{j['stability_margin']:.3g}")
    assert_fits(out, width, numbers)


def test_tree_is_not_wrapped_into_a_pipe(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.delenv("COLUMNS", raising=False)
    _, piped = run(["tree", str(SPEC)], capsys)
    out = tmp_path / "tree.txt"
    run(["tree", str(SPEC), "-o", str(out)], capsys)
    for text in (piped, out.read_text()):
        hand = [line for line in text.splitlines() if "hand_link" in line]
        # one line per link: the seed's joint with all its parts (pi/2 to 6 digits)
        assert len(hand) == 1 and hand[0].endswith("effort 100 N·m, velocity 100 rad/s")
        assert "[0, 1.5708] rad" in hand[0]


@pytest.mark.parametrize("width", WIDTHS)
def test_tree_wraps_between_parts_at_a_terminal_width(
    width: int, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("COLUMNS", str(width))
    _, out = run(["tree", str(SPEC)], capsys)
    assert max(len(line) for line in out.splitlines()) <= width
    flat = " ".join(re.sub(r"^[│ ]*(?:[├└]── )?", "", line) for line in out.splitlines())
    for part in ("[0, 1.5708] rad", "effort 100 N·m", "velocity 100 rad/s", "axis (0 1 0)"):
        assert part in flat
