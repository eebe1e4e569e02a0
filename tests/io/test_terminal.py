"""Terminal layout: numbers are never cut at any width, names wrap, pipes get whole lines."""

from __future__ import annotations

import io
import random
import re

import pytest
from rich.console import Console
from rich.text import Text

from armcli.io import terminal
from armcli.io.terminal import Column, FitTable, Hanging, fold, wrap_parts

WIDTHS = (30, 40, 60, 80, 100, 120, 200)


def _render(renderable: object, width: int) -> str:
    buf = io.StringIO()
    Console(file=buf, width=width, highlight=False).print(renderable, crop=False)
    return buf.getvalue()


def _tokens(text: str) -> set[str]:
    return set(text.split())


def _random_table(rng: random.Random, groups: bool) -> FitTable:
    """A table with long joint names and numbers in the formats armcli prints."""
    cols = [Column("joint", number=False), Column("type", number=False)]
    cols += [Column(f"q{i}\n[rad]") for i in range(rng.randint(3, 8))]
    t = FitTable(cols, title="a title that is long enough to wrap at narrow widths", caption="c")
    for r in range(rng.randint(1, 6)):
        if groups and r % 2 == 0:
            t.add_group(f"group_{r}_" + "x" * rng.randint(0, 40))
        name = "_".join(rng.choice(["arm", "base", "forearm", "hand", "joint"]) for _ in range(5))
        nums = [
            rng.choice(["{:.4g}", "{:+.4f}", "{:.3g}", "{:.1f}"]).format(
                rng.uniform(-1, 1) * 10 ** rng.randint(-6, 6)
            )
            for _ in cols[2:]
        ]
        t.add_row(name, rng.choice(["revolute", "continuous", "prismatic"]), *nums)
    return t


@pytest.mark.parametrize("seed", range(12))
def test_numbers_stay_whole_at_every_width(seed: int) -> None:
    rng = random.Random(seed)
    t = _random_table(rng, groups=seed % 2 == 1)
    numbers = [
        cell.plain
        for kind, row in t.items
        if kind == "row"
        for cell, col in zip(row, t.columns, strict=True)
        if col.number
    ]
    for width in WIDTHS:
        out = _render(t, width)
        assert "…" not in out
        missing = [n for n in numbers if n not in _tokens(out)]
        assert not missing, (width, missing, out)
        if t.widths(width) is not None:  # drawn as a table: it fits
            assert max(len(line) for line in out.splitlines()) <= width, out


def test_table_when_it_fits_records_below() -> None:
    t = FitTable([Column("joint", number=False), Column("kp"), Column("kd")])
    t.add_row("arm_base_forearm_joint", "1.742e+04", "3.48")
    assert t.natural_width() == len("arm_base_forearm_joint") + 9 + 4 + 2 * terminal.GAP
    wide = _render(t, 80).splitlines()
    assert wide[-1].split() == ["arm_base_forearm_joint", "1.742e+04", "3.48"]
    narrow = _render(t, 20)  # below NAME_MIN + the numbers: one block per row
    assert "arm_base_forearm_joint" in narrow.replace("\n", "")  # the name may wrap
    assert "kp 1.742e+04" in narrow
    assert "kd 3.48" in narrow


def test_cells_wrap_between_words_never_inside_a_name() -> None:
    assert [x.plain for x in fold(Text("worst in range"), 8)] == ["worst in", "range"]
    # issue 31: `base_right_` / `wheel_joint` and paths cut mid-word
    t = FitTable([Column("joint", number=False), Column("type", number=False), Column("kp")])
    for name in ("base_right_wheel_joint", "urdf/my_robot_description/meshes/base.stl"):
        t.add_row(name, "continuous", "1.742e+04")
    for width in (80, 60, 50, 40):
        out = _render(t, width)
        assert "base_right_wheel_joint" in out.split(), (width, out)
        assert "urdf/my_robot_description/meshes/base.stl" in out.split(), (width, out)


def test_wrap_parts_breaks_only_between_parts() -> None:
    parts = [Text(p) for p in ("revolute", "axis (0 1 0)", "[0, 1.5708] rad", "effort 100 N·m")]
    for width in range(10, 60):
        lines = [x.plain for x in wrap_parts(parts, width, "", "  ")]
        joined = " ".join(line.strip() for line in lines)
        for p in parts:
            assert p.plain in joined  # every part whole, in order
        assert all(len(line) <= max(width, 2 + 16) for line in lines)


def test_hanging_indent_has_no_trailing_spaces() -> None:
    body = Text("word " * 40 + "1.742e+04 end")
    out = _render(Hanging(Text("warning"), body, 8), 50)
    lines = out.splitlines()
    assert lines[0].startswith("warning word")
    assert all(line == line.rstrip() for line in lines)
    assert all(line.startswith(" " * 8) for line in lines[1:])
    assert "1.742e+04" in _tokens(out)


def test_layout_width_columns_terminal_and_pipe(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "80")
    assert terminal.layout_width(io.StringIO()) == 80
    monkeypatch.delenv("COLUMNS")
    assert terminal.layout_width(io.StringIO()) is None  # a pipe: natural width
    buf = io.StringIO()
    con = terminal.console(buf)
    con.print(Text("x " * 300 + "end"))
    assert len(buf.getvalue().splitlines()) == 1  # not hard-wrapped into a file


def test_unbounded_console_writes_no_padding() -> None:
    buf = io.StringIO()
    t = FitTable([Column("name", number=False), Column("value")])
    t.add_row("a", "1")
    terminal.console(buf, terminal.UNBOUNDED).print(t)
    assert all(len(line) < 20 for line in buf.getvalue().splitlines())
    assert re.search(r"^a +1$", buf.getvalue(), re.M)


def test_fit_line_keeps_indent_words_and_no_workflow_command_at_a_line_start(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from armcli.io.terminal import fit_line

    monkeypatch.setenv("COLUMNS", "30")
    text = "    an indented line long enough to wrap twice over here"
    lines = fit_line(text).splitlines()
    assert lines[0].startswith("    an") and all(ln.startswith("      ") for ln in lines[1:])
    assert " ".join(fit_line(text).split()) == " ".join(text.split())  # every word, whole
    long = "error: /a/path/longer/than/thirty/columns.yaml: not found"
    assert fit_line(long).splitlines()[0] == "error: /a/path/longer/than/thirty/columns.yaml:"
    sneaky = "wrote a file called x ::add-mask::secret into out"
    assert not any(ln.lstrip().startswith("::") for ln in fit_line(sneaky).splitlines())


def test_a_unit_or_an_equals_sign_never_starts_a_line() -> None:
    """Issue 40: `render` ended `tool at (0.450, 0.000, 0.020)` / `m`; `check`, `z` / `= 0.000`."""
    from armcli.io.wrap import spans

    for plain, width in (("tool at (0.450, 0.000, 0.020) m", 29), ("ground at z = 0.000 m", 11)):
        lines = [plain[a:b] for a, b in spans(plain, width, width)]
        assert " ".join(lines) == plain and all(len(ln) <= width for ln in lines), lines
        assert not any(ln.split()[0] in ("m", "=") for ln in lines), lines
    # a unit whose number cannot go down with it (the pair is wider than a line) goes alone
    assert spans("ab cd 1234567 m", 13, 6) == [(0, 13), (14, 15)]


def test_a_table_title_and_caption_wrap_under_their_indent() -> None:
    """Issue 40: `check`'s balance table title and caption went on flush left."""
    t = FitTable([Column("pose", number=False), Column("x\n[m]")], title="static balance " * 5,
                 caption="support polygon " * 5)  # fmt: skip
    t.add_row("home", "0.1500")
    lines = _render(t, 40).splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("pose"))
    (caption,) = (i for i, ln in enumerate(lines) if ln.startswith("support"))
    assert lines[0].startswith("static") and head > 1 and caption < len(lines) - 1, lines
    continued = lines[1:head] + lines[caption + 1 :]
    assert all(ln.startswith("  ") for ln in continued), lines
