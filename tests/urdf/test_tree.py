"""`armcli tree`: the kinematic tree against the spec it was built from and against urdfdom."""

from __future__ import annotations

import io
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from armcli.check.findings import Collector
from armcli.check.structure import check as check_structure
from armcli.errors import InputError
from armcli.spec.load import load_spec
from armcli.urdf.read import parse_urdf
from armcli.urdf.tree import KinematicTree, parse_tree, to_dot, to_rich, tree_from_urdf
from armcli.view.scene import load_robot
from tests.helpers import BAD_INPUTS, run_cli

LIMIT_TOL = 1e-9  # [rad] limits pass through xacro as shortest-repr decimals of the spec value
CHAIN = ("arm_base_link", "forearm_link", "hand_link")  # the seed's arm, root to tip
LABEL_TOL = 1e-5  # urdf_to_graphviz prints C++ ostream's 6 significant digits


@pytest.fixture(scope="module")
def robot(default_spec_path: Path):
    return load_robot(default_spec_path)


def test_tree_matches_the_spec(robot, default_spec_path: Path) -> None:
    """Every spec joint appears with its parent, child, type and limits; the root is the base."""
    spec = load_spec(default_spec_path)
    tree = parse_tree(robot.xml, robot.source)
    assert tree.root == "base_footprint"  # the only spec link that is no joint's child
    assert set(tree.links) == set(spec.all_links())
    by_name = {j.name: j for j in tree.joints}
    assert set(by_name) == set(spec.all_joints())
    for name, sj in spec.all_joints().items():
        tj = by_name[name]
        assert (tj.parent, tj.child, tj.type) == (sj.parent, sj.child, sj.type)
        assert tj.origin.xyz == pytest.approx(sj.origin.xyz, abs=LIMIT_TOL)
        if sj.limit is not None:
            assert tj.limit is not None
            assert tj.limit.lower == pytest.approx(sj.limit.lower, abs=LIMIT_TOL)
            assert tj.limit.upper == pytest.approx(sj.limit.upper, abs=LIMIT_TOL)
            assert tj.limit.effort == sj.limit.effort
    # The seed: two revolute arm joints, 0..pi/2, effort 100, velocity 100.
    assert [j.name for j in tree.movable() if j.type == "revolute"] == [
        "arm_base_forearm_joint",
        "forearm_hand_joint",
    ]


def test_rich_tree_shows_links_types_and_limits(robot) -> None:
    from rich.console import Console

    buf = io.StringIO()
    Console(file=buf, width=200).print(to_rich(parse_tree(robot.xml)))
    lines = buf.getvalue().splitlines()
    assert lines[0].startswith("base_footprint")
    hand = next(ln for ln in lines if "hand_link" in ln)
    # pi/2 = 1.5708 to 6 significant digits; effort and velocity from the seed.
    assert "forearm_hand_joint: revolute, axis (0 1 0), [0, 1.5708] rad" in hand
    assert "effort 100 N·m, velocity 100 rad/s" in hand
    # hand_link hangs below forearm_link below arm_base_link: deeper indentation each step.
    col = [next(ln.index(n) for ln in lines if f"{n}  " in ln) for n in CHAIN]
    assert col == sorted(col) and len(set(col)) == len(CHAIN)


def _edges(dot: str) -> list[tuple[str, str, list[float]]]:
    """(tail, head, numbers in the label) for every edge of a DOT file, in file order."""
    out = []
    for m in re.finditer(r'^"([^"]+)" -> "([^"]+)"(?: \[label="([^"]*)"\])?', dot, re.M):
        nums = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", m.group(3) or "")]
        out.append((m.group(1), m.group(2), nums))
    return out


def test_dot_matches_urdf_to_graphviz(robot, tmp_path: Path) -> None:
    """Same link boxes, same edges in the same order, same origins as urdfdom's own tool."""
    exe = shutil.which("urdf_to_graphviz")
    if exe is None:
        pytest.skip("urdf_to_graphviz not installed (Debian liburdfdom-tools; `make sysdeps`)")
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(robot.xml)
    subprocess.run([exe, str(urdf), "ref"], cwd=tmp_path, capture_output=True, timeout=30)
    ref = (tmp_path / "ref.gv").read_text()
    ours = to_dot(parse_tree(robot.xml))
    boxes = re.compile(r'^"([^"]+)" \[label="\1"\];$', re.M)
    assert boxes.findall(ours) == boxes.findall(ref)
    ref_edges, our_edges = _edges(ref), _edges(ours)
    assert [e[:2] for e in our_edges] == [e[:2] for e in ref_edges]
    for (_, _, a), (_, _, b) in zip(our_edges, ref_edges, strict=True):
        assert a == pytest.approx(b, abs=LABEL_TOL)


def _urdf(body: str) -> str:
    return f'<robot name="r">{body}</robot>'


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ('<link name="a"/><link name="b"/>', "exactly one root link"),
        (
            '<link name="a"/><joint name="j" type="fixed"><parent link="a"/>'
            '<child link="zz"/></joint>',
            "unknown child link 'zz'",
        ),
        (
            '<link name="a"/><link name="b"/><joint name="j" type="hinge"><parent link="a"/>'
            '<child link="b"/></joint>',
            "unknown type 'hinge'",
        ),
        (
            '<link name="a"/><link name="b"/><joint name="j" type="fixed"><parent link="a"/>'
            '<child link="b"/><origin xyz="0 nan 0"/></joint>',
            "non-finite",
        ),
    ],
)
def test_bad_urdf_is_one_clear_error(body: str, message: str) -> None:
    with pytest.raises(InputError, match=message) as info:
        parse_tree(_urdf(body), "bad.urdf")
    assert info.value.file == "bad.urdf"


def test_entities_are_refused() -> None:
    xml = '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]><robot name="&x;"/>'
    with pytest.raises(InputError, match="DOCTYPE"):
        parse_tree(xml, "evil.urdf")


def test_cli_tree_text_dot_and_bad_format(root: Path, tmp_path: Path) -> None:
    text = run_cli(["tree"], root)
    assert text.returncode == 0, text.stderr
    assert "forearm_link" in text.stdout and "revolute" in text.stdout
    out = tmp_path / "robot.gv"
    dot = run_cli(["tree", "urdf/my_robot.urdf", "--format", "dot", "-o", str(out)], root)
    assert dot.returncode == 0, dot.stderr
    assert out.read_text().startswith("digraph G {")
    bad = run_cli(["tree", "--format", "svg"], root)
    assert bad.returncode == 2
    assert bad.stderr.strip() == "error: --format: unknown value 'svg'; valid: text, dot"


Names = tuple[str, ...]


def _joint(name: str, parent: str, child: str, kind: str = "revolute") -> str:
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
    )


def _links(*names: str) -> str:
    return "".join(f'<link name="{n}"/>' for n in names)


@pytest.mark.parametrize(
    ("body", "roots", "orphans", "extra", "refused"),
    [
        (_links("b", "a"), ("b", "a"), (), (), "exactly one root link, found b, a"),
        (_links("a", "b") + _joint("j", "a", "b") + _joint("k", "b", "a"), (), (), (), "none"),
        (_links("a", "zz") + _joint("j", "a", "missing"), ("a", "zz"), (), (), "unknown child"),
        (  # a cycle no root reaches
            _links("a", "b", "c", "d") + _joint("j", "a", "b")
            + _joint("k", "c", "d") + _joint("l", "d", "c"),
            ("a",), ("c", "d"), (), "not one tree",
        ),
        (  # a link held by a second joint that loops back to it: `tree` once never ended
            _links("a", "b") + _joint("j", "a", "b") + _joint("k", "b", "b"),
            ("a",), (), ("k",), "not one tree",
        ),
        (_links("a", "b", "b") + _joint("j", "a", "b"), ("a",), (), (), "'b' is defined more"),
    ],
)  # fmt: skip
def test_one_tree_type_describes_malformed_trees_and_the_strict_one_refuses_them(
    body: str, roots: Names, orphans: Names, extra: Names, refused: str
) -> None:
    urdf = parse_urdf(_urdf(body).encode(), "bad.urdf")
    tree = KinematicTree.of(urdf)
    assert (tree.roots, tree.orphans) == (roots, orphans)
    assert tuple(j.name for j in tree.extra_parents) == extra
    assert tree.root == (min(roots) if roots else None)
    walked = [j.name for _, j in tree.walk()]  # it ends: one parent joint per link
    assert len(walked) == len(set(walked)) <= len(tree.parent_joint)
    assert check_structure(urdf, Collector("bad.urdf")) == tree  # check's tree is this one
    with pytest.raises(InputError, match=refused):
        tree_from_urdf(urdf)


def test_check_and_tree_build_the_same_tree_for_every_bad_urdf() -> None:
    for path in sorted((BAD_INPUTS / "urdf").glob("*.urdf")):
        try:
            urdf = parse_urdf(path.read_bytes(), str(path))
        except InputError:
            continue  # refused before any tree: not a URDF, too large, ...
        tree = check_structure(urdf, Collector(str(path)))
        assert tree == KinematicTree.of(urdf), path.name
        if not tree.extra_parents and not tree.orphans and len(tree.roots) == 1:
            reached = {tree.root} | {str(j.child) for _, j in tree.walk()}
            assert reached == set(tree.links), path.name
