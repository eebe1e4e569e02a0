"""Parts are bounded by what they expand to (issue 27): a 19 kB spec of 100 placements of a
50-link part (5001 links) kept `build` busy past 60 s. The expanded robot is refused when it
has more links than armcli's bound on robot size (the URDF reader's, 300), before any part is
expanded; up to that bound the work is linear in the number of links.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from armcli.compiler.expand import expand_urdfs
from armcli.errors import SpecError
from armcli.spec.load import load_spec
from armcli.urdf.read import MAX_URDF_DOF, MAX_URDF_LINKS, parse_urdf


def chain_part_spec(n_links: int, n_placements: int, prefix: str = "p{k}_") -> str:
    """A base link and `n_placements` placements of an `n_links` revolute chain."""
    out = ["name: bomb", "parts:", "  seg:", "    links:"]
    box = "{geometry: {box: {size: [0.01, 0.01, 0.01]}}, mass: 0.1}"
    out += [f"      l{i}: {box}" for i in range(n_links)]
    out.append("    joints:" + ("" if n_links > 1 else " {}"))
    lim = "{lower: -1, upper: 1, effort: 1, velocity: 1}"
    out += [
        f"      j{i}: {{type: revolute, parent: l{i - 1}, child: l{i}, limit: {lim}}}"
        for i in range(1, n_links)
    ]
    out += ["arm:", "  links:", f"    base_link: {box}", "  joints: {}", "  parts:"]
    out += [
        f"    - {{part: seg, prefix: {prefix.format(k=k)}, parent: base_link, joint: a{k}}}"
        for k in range(n_placements)
    ]
    return "\n".join(out) + "\n"


def test_parts_beyond_the_robot_bound_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "bomb.yaml"
    path.write_text(chain_part_spec(50, 100))
    with pytest.raises(SpecError) as info:
        load_spec(path)
    line = str(info.value)
    assert "arm.parts" in line and "5001 links" in line and str(MAX_URDF_LINKS) in line, line


def test_parts_beyond_the_dof_bound_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "dof.yaml"
    path.write_text(chain_part_spec(30, 5))  # 5 x 29 = 145 revolute joints, 151 links
    with pytest.raises(SpecError, match=rf"145 degrees of freedom.*{MAX_URDF_DOF}"):
        load_spec(path)


def test_parts_up_to_the_bound_build(tmp_path: Path) -> None:
    # 1 base link + 5 placements x 25 links = 126 links and 5 x 24 = 120 revolute joints,
    # under both bounds (300 links, 128 degrees of freedom): built and read back
    path = tmp_path / "ok.yaml"
    path.write_text(chain_part_spec(25, 5))
    spec = load_spec(path)
    urdf = parse_urdf(expand_urdfs(spec)["standalone_arm.urdf"], "ok.urdf")
    assert len(urdf.links) == 126
    assert len(spec.movable_arm_joints()) == 5 * 24


@pytest.mark.parametrize("prefix", ["../../x{k}/", "/abs{k}_", "a/../b{k}_"])
def test_a_prefix_may_not_climb_or_be_absolute(prefix: str, tmp_path: Path) -> None:
    path = tmp_path / "prefix.yaml"
    path.write_text(chain_part_spec(2, 1, prefix))
    with pytest.raises(SpecError, match=r"parts\[0\]\.prefix"):
        load_spec(path)
