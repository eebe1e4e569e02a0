"""Constructs from public robot descriptions (issue 32), each in a small fixture of our own.

The public files themselves are never committed: each fixture reproduces one construct
(named in its header comment) and each test failed before the fix it guards.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tests.helpers import FIXTURES, run_main

REAL = FIXTURES / "real_robots"
SHARED = REAL / "shared_names.urdf"
HOLD_KNEE = "{joint_names: [knee], points: [{positions: [0.1], time_from_start: 1.0}]}"


def test_a_link_and_a_joint_sharing_a_name_simulate_and_check(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """ANYmal C: `Several frames match` was an internal error; the tool is the link `knee`."""
    args = ["simulate", "--urdf", SHARED, "--kp", "50", "--kd", "2", "-m", HOLD_KNEE]
    code, out, err = run_main(args, capsys)
    assert code == 0, err
    # The tool point is the link `knee`'s origin: 0.1 m (joint hip) + 0.2 m (joint knee) up.
    assert "end effector knee in base_link" in out
    assert "0.3000) m" in out
    code, out, err = run_main(["check", SHARED], capsys)
    assert code == 0, err
    assert "internal error" not in err
    assert "reach of knee" in out
    # `plan` looks the tool up too (its default tool point is the link `knee`).
    code, out, err = run_main(
        ["plan", "--urdf", SHARED, "--from", "0,0", "--to", "0.5,0.5", "--joints", "hip,knee"],
        capsys,
    )
    assert code == 0, err
    assert "certified" in out


def test_stray_text_after_a_kept_element_imports(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A course student's URDF: `XMLSyntaxError: Extra content` was an internal error."""
    out_spec = tmp_path / "armcli.yaml"
    code, out, err = run_main(
        ["import", REAL / "stray_text.urdf", "-o", out_spec, "--strict"], capsys
    )
    assert code == 0, err
    assert "gives back the same URDF" in out
    assert "<self_collide>1</self_collide>" in out_spec.read_text()


def test_a_missing_texture_is_one_warning_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """PR2: trimesh printed a traceback per missing texture image; now one warning line."""
    png = tmp_path / "textured.png"
    code, out, err = run_main(["render", REAL / "textured.urdf", "-o", png], capsys)
    assert code == 0, err
    assert png.is_file() and "wrote" in out
    assert "Traceback" not in err
    warnings = [ln for ln in err.splitlines() if "missing_texture.png" in ln]
    assert len(warnings) == 1 and warnings[0].startswith("warning: ")
    assert "meshes/textured.dae" in warnings[0]
    # `check` reads the same mesh for the ground contacts: no traceback there either.
    code, out, err = run_main(["check", REAL / "textured.urdf"], capsys)
    assert code == 0, err
    assert "Traceback" not in out + err


ROTOR_MASS, ROTOR_RADIUS = 0.089, 0.035  # [kg], [m] Go1's hip rotor (fixture header)
ROTOR_IXX = 0.000111842  # [kg·m²] its written moment about the disc's axis
BOUND_RTOL = 1e-9


def test_a_visual_only_primitive_is_a_warning(capsys: pytest.CaptureFixture[str]) -> None:
    """Go1: its rotor discs are visual only; 2.6 % over the bound was an error that blocked."""
    code, out, err = run_main(
        ["check", REAL / "rotor_visual_only.urdf", "--format", "json"], capsys
    )
    assert code == 0, err
    (f,) = [
        f for f in json.loads(out)["files"][0]["findings"] if f["values"].get("link") == "hip_rotor"
    ]
    assert f["rule"] == "inertia-exceeds-visual" and f["severity"] == "warning"
    # The disc's axis is the geometry's z; all the mass on the rim gives m r² (closed form).
    assert f["values"]["bound"][2] == pytest.approx(ROTOR_MASS * ROTOR_RADIUS**2, rel=BOUND_RTOL)
    assert f["values"]["about_centre"][2] == pytest.approx(ROTOR_IXX, rel=BOUND_RTOL)


def test_wheels_on_passive_spring_joints_stand_on_the_ground(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """LoCoBot's Create 3: zero-limit wheel drops were errors, and no wheel touched."""
    code, out, err = run_main(["check", REAL / "wheel_drop.urdf"], capsys)
    assert code == 0, err
    assert "limit-effort-velocity" not in out + err
    assert "passive joint(s) wheel_drop_left_joint, wheel_drop_right_joint" in out
    # The lowest points within 5 mm: the caster's bottom and the wheels' tread edges at
    # y = ±(0.117 + 0.01) m, 0.254 m across; 2 % of it is 5.1 mm, which takes the wheels
    # 2.45 mm above the caster; the report says so.
    assert (
        "static balance on caster_link, left_wheel, right_wheel "
        "(the links within 5.1 mm of the lowest point at q = 0)"
    ) in out
    # The polygon: the caster's bottom (-0.12, 0) and the wheels below their axles (0, ±0.117).
    assert "support polygon (-0.120, 0.000) (0.000, -0.117) (0.000, 0.117) m" in out


def test_zero_limits_stay_an_error_where_nothing_says_passive(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without any <transmission>, a zero effort limit may be a typo: still an error."""
    text = (REAL / "wheel_drop.urdf").read_text()
    bare = re.sub(r"\s*<transmission.*?</transmission>", "", text, flags=re.S)
    assert "transmission>" not in bare
    (tmp_path / "bare.urdf").write_text(bare)
    code, out, _ = run_main(["check", tmp_path / "bare.urdf"], capsys)
    assert code == 1 and "limit-effort-velocity" in out


def test_an_inertia_tensor_error_leaves_the_balance_running(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Fetch, Stretch, PR2: `--ignore` gave 0 errors and still no tip-over numbers.

    A tensor breaking the triangle inequality moves no centre of mass: the balance runs,
    the dynamics (which need the tensor) do not.
    """
    text = (REAL / "wheel_drop.urdf").read_text()
    good = 'ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.038"'
    assert good in text
    bad = tmp_path / "triangle.urdf"  # 0.01 + 0.01 < 0.038: no real body has these moments
    bad.write_text(text.replace(good, 'ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.038"'))
    for ignore in ([], ["--ignore", "inertia-triangle"]):
        code, out, _ = run_main(["check", bad, *ignore], capsys)
        assert code == (0 if ignore else 1)
        assert "static balance on caster_link, left_wheel, right_wheel" in out
        assert "support polygon (-0.120, 0.000) (0.000, -0.117) (0.000, 0.117) m" in out
        assert "dynamics checks skipped" in out


LINES = REAL / "xacro_lines"
TOP, PARTS = LINES / "robot.urdf.xacro", LINES / "parts" / "caster.xacro"


def _line_of(path: Path, needle: str) -> int:
    """The 1-based line of the fixture text that holds `needle` (once)."""
    (k,) = [i for i, row in enumerate(path.read_text().splitlines(), 1) if needle in row]
    return k


def test_xacro_findings_land_on_the_users_own_lines(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """TurtleBot3: a caster inertia defined by a macro in an included file was reported at
    the expanded document's line, with no `line=` for GitHub and no SARIF region."""
    inertia = _line_of(PARTS, "<inertia ixx")  # the start tag, not where it ends (+2)
    call = _line_of(TOP, "<xacro:caster ")
    monkeypatch.chdir(LINES)  # annotations name files relative to the repository
    code, out, _ = run_main(["check", TOP, "--format", "github"], capsys)
    assert code == 1
    (line,) = [ln for ln in out.splitlines() if "inertia-exceeds-geometry" in ln]
    assert line.startswith(f"::error file=parts/caster.xacro,line={inertia},")
    assert f"through the macro call at robot.urdf.xacro:{call}" in line
    code, out, _ = run_main(["check", TOP, "--format", "sarif"], capsys)
    (result,) = [
        r
        for r in json.loads(out)["runs"][0]["results"]
        if r["ruleId"] == "inertia-exceeds-geometry"
    ]
    place = result["locations"][0]["physicalLocation"]
    assert place["artifactLocation"]["uri"] == "parts/caster.xacro"
    assert place["region"] == {"startLine": inertia}
    (called,) = result["relatedLocations"]
    assert called["physicalLocation"]["artifactLocation"]["uri"] == "robot.urdf.xacro"
    assert called["physicalLocation"]["region"] == {"startLine": call}


def test_long_arms_do_not_widen_the_contact_tolerance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A dual-arm Tiago spans 2.5 m at the zero pose: 2 % of that took its base's underside,
    49 mm up, as a ground contact (and its round outline made the balance search 12 s)."""
    arms = """
  <joint name="arms_joint" type="fixed">
    <parent link="base_link"/>
    <child link="arms"/>
    <origin xyz="0 0 0.5"/>
  </joint>
  <link name="arms">
    <collision><geometry><box size="3.0 0.05 0.05"/></geometry></collision>
    <inertial>
      <mass value="0.1"/>
      <inertia ixx="4e-05" ixy="0" ixz="0" iyy="0.075" iyz="0" izz="0.075"/>
    </inertial>
  </link>
</robot>"""
    wide = tmp_path / "wide.urdf"  # the base cylinder's bottom is 50 mm above the ground
    wide.write_text((REAL / "wheel_drop.urdf").read_text().replace("</robot>", arms))
    code, out, err = run_main(["check", wide], capsys)
    assert code == 0, err
    assert (
        "static balance on caster_link, left_wheel, right_wheel "
        "(the links within 5.1 mm of the lowest point at q = 0)"
    ) in out
