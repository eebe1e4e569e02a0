"""Constructs from public robot descriptions (issue 32), each in a small fixture of our own.

The public files themselves are never committed: each fixture reproduces one construct
(named in its header comment) and each test failed before the fix it guards.
"""

from __future__ import annotations

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
