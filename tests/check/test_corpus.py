"""`check` on third-party URDFs nobody here wrote (the example-robot-data package), with
MuJoCo's model compiler as an independent oracle for the inertia-validity rules."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import pytest
from lxml import etree

from armcli.check.options import CheckOptions
from armcli.check.run import check_urdf
from armcli.errors import ArmcliError
from armcli.urdf.read import read_urdf

# Error-level inertia rules whose verdict MuJoCo's compiler also gives: it refuses
# non-positive mass/inertia of moving bodies ("mass and inertia of moving bodies must
# be larger than mjMINVAL"), non-positive-definite full inertias ("inertia must have
# positive eigenvalues") and triangle-inequality violations ("A + B >= C").
INERTIA_RULES = {"mass-nonpositive", "inertia-not-pd", "inertia-triangle"}
MUJOCO_INERTIA_ERRORS = ("mass and inertia", "inertia must", "positive eigenvalues")


def _corpus() -> list[Path]:
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return []
    files = [Path(str(dist.locate_file(f))) for f in dist.files or () if str(f).endswith(".urdf")]
    return sorted(p for p in files if "/robots/" in p.as_posix())


CORPUS = _corpus()
IDS = [p.as_posix().split("/robots/")[1] for p in CORPUS]


def test_corpus_is_there() -> None:
    if not CORPUS:
        pytest.skip("example-robot-data is not installed (pip install -e '.[dev]')")
    assert len(CORPUS) >= 20


def _check(path: Path):
    try:
        return check_urdf(read_urdf(path), CheckOptions())
    except ArmcliError as exc:  # unusable input is a clean exit 2, not a crash
        assert exc.exit_code == 2
        return None


@pytest.mark.parametrize("path", CORPUS, ids=IDS)
def test_check_runs_without_crashing(path: Path) -> None:
    result = _check(path)
    if result is not None:
        for f in result.findings:
            assert f.message and f.severity in ("error", "warning")


def mujoco_verdict(path: Path) -> str | None:
    """MuJoCo's verdict on the URDF's inertias: the error text, or None if it compiles.

    Geometry is dropped (MuJoCo cannot read .dae meshes and the rules are about
    inertia) and the compiler is told to take inertias as written: no inertia
    from geometry, no balancing, no lower bounds on mass or inertia.
    """
    import mujoco

    root = etree.parse(str(path)).getroot()
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for el in link.findall(tag):
                link.remove(el)
    for el in root.findall("mujoco"):
        root.remove(el)
    extra = etree.SubElement(root, "mujoco")
    etree.SubElement(
        extra,
        "compiler",
        inertiafromgeom="false",
        balanceinertia="false",
        boundmass="0",
        boundinertia="0",
    )
    try:
        mujoco.MjModel.from_xml_string(etree.tostring(root).decode())
    except ValueError as exc:
        return str(exc)
    return None


@pytest.mark.parametrize("path", CORPUS, ids=IDS)
def test_inertia_verdict_agrees_with_mujoco(
    path: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("mujoco")
    monkeypatch.chdir(tmp_path)  # MuJoCo appends its warnings to ./MUJOCO_LOG.TXT
    result = _check(path)
    if result is None:
        pytest.skip("not a usable URDF (armcli exits 2)")
    ours = sorted({f.rule for f in result.findings if f.rule in INERTIA_RULES})
    theirs = mujoco_verdict(path)
    if theirs is not None and not any(m in theirs for m in MUJOCO_INERTIA_ERRORS):
        pytest.skip(f"MuJoCo refuses this URDF for another reason: {theirs.splitlines()[0]}")
    # MuJoCo stops at its first error, so only the verdicts are compared, not the counts.
    assert bool(ours) == (theirs is not None), (ours, theirs)
