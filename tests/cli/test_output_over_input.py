"""`-o` naming a file the command reads, or a hard link to one, is refused first (issue 42).

Before: `plan SPEC -o SPEC`, `plan --scene S -o S`, `simulate --cmd-vel C -o <a hard link
to C>`, `import A -o A --force` and the other writers replaced their own input with
their output (`expand` already refused it). Each case runs through the real CLI as the
invoking user (root on CI) and as an ordinary user; the input must stay byte-identical.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

from tests.helpers import DEFAULT_SPEC, ROOT
from tests.urdf.ordinary_user import Run

DRIVE = ROOT / "specs" / "trajectories" / "drive.yaml"
URDF = ROOT / "tests" / "fixtures" / "import" / "six_axis_gripper.urdf"
SCENE = ROOT / "tests" / "fixtures" / "plan" / "box_in_the_way.yaml"

PLAN = ("plan", "{spec}", "--to", "reach")
DRIVE_ARGS = ("simulate", "{spec}", "--cmd-vel", "{drive}", "--duration", "0.5")
# (arguments, the input file the output names: itself, or a hard link with this name)
CASES: dict[str, tuple[tuple[str, ...], str, str | None]] = {
    "plan -o the spec": ((*PLAN, "-o", "{out}"), "spec", None),
    "plan -o a link to the spec": ((*PLAN, "-o", "{out}"), "spec", "p.yaml"),
    "plan -o the scene": ((*PLAN, "--scene", "{scene}", "-o", "{out}"), "scene", None),
    "simulate -o a link to the cmd-vel file": ((*DRIVE_ARGS, "-o", "{out}"), "drive", "run.csv"),
    "simulate --plot a link to the spec": ((*DRIVE_ARGS, "--plot", "{out}"), "spec", "p.png"),
    "import -o the URDF --force": (("import", "{urdf}", "-o", "{out}", "--force"), "urdf", None),
    "tune --output a link to the spec": (("tune", "{spec}", "--output", "{out}"), "spec", "t.json"),
    "render -o a link to the spec": (("render", "{spec}", "-o", "{out}"), "spec", "r.png"),
    "tree -o the spec": (("tree", "{spec}", "-o", "{out}"), "spec", None),
    "export mjcf -o a link to the spec": (
        ("export", "mjcf", "{spec}", "-o", "{out}"),
        "spec",
        "m.xml",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_output_over_an_input_is_refused(case: str, run: tuple[Path, Run]) -> None:
    work, cli = run
    args, target, link = CASES[case]
    files = {"spec": DEFAULT_SPEC, "drive": DRIVE, "urdf": URDF, "scene": SCENE}
    paths = {}
    for key, src in files.items():
        paths[key] = work / src.name
        shutil.copy(src, paths[key])
    out = paths[target]
    if link is not None:
        out = work / link
        os.link(paths[target], out)
    before = paths[target].read_bytes()
    proc = cli(*(a.format(out=out, **paths) for a in args))
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("error: ") and len(proc.stderr.splitlines()) == 1, proc.stderr
    assert f"is the input file {paths[target]}; write elsewhere" in proc.stderr, proc.stderr
    assert paths[target].read_bytes() == before
