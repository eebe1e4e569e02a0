"""`build`: real xacro expansion; check_urdf and Pinocchio accept the URDFs with seed values."""

from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import armcli.compiler.expand as build_mod
from armcli.compiler.expand import build, stale_files
from armcli.errors import BuildError
from tests.helpers import run_cli

ARM_JOINTS = ["arm_base_forearm_joint", "forearm_hand_joint"]
# Seed: arm 0.5 + 0.3 + 0.3 kg; base 5 kg + 2 wheels x 1 kg + caster 0.5 kg.
ARM_MASS = 1.1
ROBOT_MASS = 8.6
# base_joint z (wheel radius 0.1) + mount z (base height 0.2) + arm base joint 0.02
# + forearm 0.3 + hand 0.3; x = mount x = base_length / 4.
TIP_AT_HOME = np.array([0.6 / 4, 0.0, 0.1 + 0.2 + 0.02 + 0.3 + 0.3])
MASS_TOL = 1e-12
POS_TOL = 1e-12


@pytest.mark.parametrize("name", ["my_robot.urdf", "standalone_arm.urdf"])
def test_check_urdf_accepts(built_dir: Path, name: str) -> None:
    exe = shutil.which("check_urdf")
    if exe is None:
        pytest.skip("check_urdf not installed (Debian liburdfdom-tools; `make sysdeps`)")
    proc = subprocess.run([exe, str(built_dir / name)], capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Successfully Parsed XML" in proc.stdout


def test_standalone_arm_in_pinocchio(built_dir: Path) -> None:
    model = pin.buildModelFromUrdf(str(built_dir / "standalone_arm.urdf"))
    names = [model.names[i] for i in range(1, model.njoints)]
    assert names == ARM_JOINTS
    np.testing.assert_array_equal(model.lowerPositionLimit, [0.0, 0.0])
    np.testing.assert_array_equal(model.upperPositionLimit, [math.pi / 2, math.pi / 2])
    np.testing.assert_array_equal(model.effortLimit, [100.0, 100.0])
    np.testing.assert_array_equal(model.velocityLimit, [100.0, 100.0])
    np.testing.assert_array_equal(model.damping, [0.1, 0.1])
    np.testing.assert_array_equal(model.friction, [0.05, 0.05])
    assert sum(i.mass for i in model.inertias) == pytest.approx(ARM_MASS, abs=MASS_TOL)
    # Forearm body: a 0.3 kg cylinder r 0.02 l 0.3 whose centre is 0.15 m up the joint frame.
    forearm = model.inertias[model.getJointId("arm_base_forearm_joint")]
    ref = pin.Inertia.FromCylinder(0.3, 0.02, 0.3)
    np.testing.assert_allclose(forearm.lever, [0, 0, 0.15], atol=POS_TOL)
    np.testing.assert_allclose(forearm.inertia, ref.inertia, rtol=1e-12)


def test_whole_robot_in_pinocchio(built_dir: Path) -> None:
    model = pin.buildModelFromUrdf(str(built_dir / "my_robot.urdf"))
    names = {model.names[i] for i in range(1, model.njoints)}
    assert names == {"base_left_wheel_joint", "base_right_wheel_joint", *ARM_JOINTS}
    assert sum(i.mass for i in model.inertias) == pytest.approx(ROBOT_MASS, abs=MASS_TOL)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    hand = data.oMf[model.getFrameId("hand_link")]
    tip = hand.act(np.array([0.0, 0.0, 0.3]))
    np.testing.assert_allclose(tip, TIP_AT_HOME, atol=POS_TOL)
    assert model.frames[model.getFrameId("base_footprint")].parentJoint == 0


def test_build_is_deterministic(tmp_path: Path, default_spec_path: Path) -> None:
    a, b = tmp_path / "a", tmp_path / "b"
    build(default_spec_path, a)
    build(default_spec_path, b)
    names = sorted(p.name for p in a.iterdir())
    assert (
        names == sorted(p.name for p in b.iterdir()) and len(names) == 10
    )  # 9 generated files + the armcli marker
    for n in names:
        assert (a / n).read_bytes() == (b / n).read_bytes(), n


def test_committed_urdf_is_fresh(root: Path, default_spec_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(root)
    assert stale_files("specs/my_robot.yaml", "urdf") == []


def test_failed_build_leaves_previous_outputs(
    tmp_path: Path, default_spec_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "urdf"
    build(default_spec_path, out)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    spec_text = default_spec_path.read_text().replace("mass: 0.5\n", "mass: 0.6\n", 1)
    changed = tmp_path / "changed.yaml"
    changed.write_text(spec_text)

    def boom(*args: object, **kwargs: object) -> bytes:
        raise BuildError("injected failure during expansion")

    monkeypatch.setattr(build_mod, "expand", boom)
    with pytest.raises(BuildError):
        build(changed, out)
    after = {p.name: p.read_bytes() for p in out.iterdir()}
    assert after == before  # nothing replaced, no temporary files left behind


def test_cli_build_check_and_stale(tmp_path: Path, default_spec_path: Path) -> None:
    out = tmp_path / "urdf"
    ok = run_cli(["build", str(default_spec_path), "-o", str(out)])
    assert ok.returncode == 0, ok.stderr
    fresh = run_cli(["build", str(default_spec_path), "-o", str(out), "--check"])
    assert fresh.returncode == 0, fresh.stderr
    (out / "arm.xacro").write_text("<robot/>")
    (out / "my_robot.urdf").unlink()
    stale = run_cli(["build", str(default_spec_path), "-o", str(out), "--check"])
    assert stale.returncode == 1
    assert f"stale: {out / 'arm.xacro'}" in stale.stderr
    assert f"stale: {out / 'my_robot.urdf'}" in stale.stderr


def test_cli_bad_spec_exit_2_and_writes_nothing(tmp_path: Path, default_spec_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(default_spec_path.read_text().replace("upper: pi/2", "upper: -1", 1))
    out = tmp_path / "out"
    proc = run_cli(["build", bad, "-o", out])
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: {bad}:")
    assert "limit.upper: must be >= lower (0)" in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not out.exists()
