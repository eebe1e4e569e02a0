"""The drive's steps between two plugin updates: compiled (`armcli.sim._drivestep`) or Python.

Per step the drive sets the rotors to the plugin's commanded wheel speeds, writes the arm's
actuator controls (the reference's ctrl row, plus g(q) / Kp of the fixed-base arm with
gravity compensation), steps MuJoCo and records the sensors and the clutch torques. Only
the plugin's update (every `update_rate` period, 20 steps on the course robot) needs Python:
`Steps.advance` runs the steps in between in one call. The compiled loop is the same
arithmetic in the same order as `_python_steps` here (tests/drive/test_step.py compares
them bit for bit); it takes mj_step's address from the libmujoco the mujoco package loaded
(ctypes) instead of linking MuJoCo, so it cannot disagree with the installed MuJoCo's structs.

Before each step k it also keeps what a path follower reads of the state (`seen[k]`: the
free joint's qpos and the wheels' speeds), so the follower can integrate its odometry after
the steps instead of inside them (`drive.job.Pilot.observe`).
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

import numpy as np

from armcli.compiled import Extension
from armcli.drive.model import DriveModel

if TYPE_CHECKING:
    from armcli.robot.model import Robot

SOURCE = Path(__file__).parents[1] / "sim" / "_native" / "drivestep.cpp"
SEEN = 9  # seen[k]: qpos[0:7] (the free joint), then the two wheels' qvel
_state: dict[str, Any] = {}


DRIVESTEP = Extension("armcli.sim._drivestep", (SOURCE,))
load = DRIVESTEP.load  # the compiled loop, or None (not built, stale, ARMCLI_NO_NATIVE)


def mj_step_address() -> int | None:
    """mj_step's address in the libmujoco the mujoco package loaded (dlopen finds the same).

    None when the package holds no libmujoco of its own (a build against a system MuJoCo):
    the drive then runs its Python steps.
    """
    import mujoco

    if "mj_step" not in _state:
        libs = sorted(Path(mujoco.__file__).parent.glob("libmujoco*"))
        if not libs:
            _state["mj_step"] = None
        else:
            _state["lib"] = ctypes.CDLL(str(libs[0]))  # already loaded: the same handle
            _state["mj_step"] = ctypes.cast(_state["lib"].mj_step, ctypes.c_void_p).value
    address: int | None = _state["mj_step"]
    return address


@dataclass
class Steps:
    """One run's stepping: MuJoCo's model and data, the arm's controls, the records."""

    m: Any  # mujoco.MjModel
    d: Any  # mujoco.MjData
    dm: DriveModel
    ctrl_arm: np.ndarray  # (T, ncols) the reference's ctrl rows (actuated joints)
    inv_kp: np.ndarray  # (ncols,)
    cols: np.ndarray  # (ncols,) the actuated joints among the arm's
    robot: Robot | None  # the fixed-base arm whose g(q) compensates gravity; None: none
    rec: np.ndarray  # (N + 1, nsensordata)
    seen: np.ndarray  # (N + 1, SEEN)
    native: Any = None  # the compiled Stepper, when there is one

    def __post_init__(self) -> None:
        self.act = np.ascontiguousarray(self.dm.arm_act[self.cols], dtype=np.int64)
        mod = load()
        if mod is not None and mj_step_address() is not None:
            self.native = _stepper(mod, self)

    def advance(self, k0: int, k1: int, rows: np.ndarray, command: np.ndarray) -> None:
        """Steps k0 .. k1 - 1: the rotors at `command` [rad/s], the arm at reference `rows`."""
        if k1 <= k0:
            return
        if self.native is not None:
            self.native.advance(k0, k1, rows, float(command[0]), float(command[1]))
        else:
            _python_steps(self, k0, k1, rows, command)


def _stepper(mod: ModuleType, s: Steps) -> Any:
    dm, d = s.dm, s.d
    i64 = np.int64
    if s.robot is not None:
        import pinocchio as pin

        buf = pin.serialization.StreamBuffer()
        s.robot.model.saveToBinary(buf)
        model: bytes | None = buf.tobytes()
        rest = np.ascontiguousarray(s.robot.rest_q(), dtype=float)
        idx_q = np.array([j.idx_q for j in s.robot.joints], dtype=i64)
        cont = np.array([j.continuous for j in s.robot.joints], dtype=np.uint8)
    else:
        model, rest, idx_q, cont = None, np.zeros(0), np.zeros(0, i64), np.zeros(0, np.uint8)
    return mod.stepper(
        step=mj_step_address(),
        m=s.m._address,
        d=d._address,
        qpos=d.qpos,
        qvel=d.qvel,
        ctrl=d.ctrl,
        sensordata=d.sensordata,
        qfrc_constraint=d.qfrc_constraint,
        rotor=np.asarray(dm.wheel_rotor, dtype=i64),
        wheel_dof=np.asarray(dm.wheel_dof, dtype=i64),
        wheel_force=np.arange(s.rec.shape[1], dtype=i64)[dm.layout.wheel_force],
        arm_qpos=np.asarray(dm.arm_qpos, dtype=i64),
        act=s.act,
        cols=np.asarray(s.cols, dtype=i64),
        inv_kp=np.ascontiguousarray(s.inv_kp, dtype=float),
        ctrl_arm=s.ctrl_arm,
        rec=s.rec,
        seen=s.seen,
        gravity_model=model,
        rest_q=rest,
        idx_q=idx_q,
        continuous=cont,
    )


def _python_steps(s: Steps, k0: int, k1: int, rows: np.ndarray, command: np.ndarray) -> None:
    """The compiled loop's steps in Python (no extension): the same arithmetic, in order."""
    import mujoco

    from armcli.drive.wheelmotor import spin

    m, d, dm, rec, seen = s.m, s.d, s.dm, s.rec, s.seen
    rotor, wheel_dof, wheel_force = dm.wheel_rotor, dm.wheel_dof, dm.layout.wheel_force
    ctrl, act, arm_qpos, cols = d.ctrl, s.act, dm.arm_qpos, s.cols
    robot = s.robot
    for k in range(k0, k1):
        seen[k, :7], seen[k, 7:] = d.qpos[:7], d.qvel[wheel_dof]
        spin(d, rotor, command)  # the plugin's motor speed (its "vel")
        j = rows[k - k0]
        if robot is None:
            ctrl[act] = s.ctrl_arm[j]
        else:
            g = robot.gravity(robot.q(d.qpos[arm_qpos]))
            ctrl[act] = s.ctrl_arm[j] + g[cols] * s.inv_kp
        mujoco.mj_step(m, d)
        rec[k] = d.sensordata
        rec[k, wheel_force] = -d.qfrc_constraint[rotor]  # drive.wheelmotor.clutch_torque


if __name__ == "__main__":  # `python -m armcli.drive.step`: are the compiled steps installed
    import sys

    if load() is None:
        print(
            "armcli: compiled drive steps unavailable (not built, or built from another "
            f"{SOURCE.name}: run make native); the drive runs its Python steps",
            file=sys.stderr,
        )
        raise SystemExit(1)
    print(f"armcli: compiled drive steps {load()}")
