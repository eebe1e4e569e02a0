"""gazebo_ros_diff_drive's wheel motor in MuJoCo: a speed held by a constraint of bounded torque.

The plugin sets each wheel joint's ODE motor: `SetParam("vel", ω)` and `SetParam("fmax",
max_wheel_torque)`. ODE solves that motor as a constraint row with the contacts: the joint
turns at exactly ω unless that takes more than fmax, in which case it gets fmax and slips
behind. There is no gain to choose.

MuJoCo has no velocity motor constraint, but its friction loss is one: a constraint that
holds a (tendon's) velocity at zero with at most `frictionloss` of force. So each wheel
gets a rotor: a body on the wheel's parent turning about the wheel's axis, of huge inertia
(ROTOR_ARMATURE), whose speed the run sets to the command before every step (`spin`: it
is the plugin's `vel`; an actuator spinning it would be seen by the constraint solver as
an explicit force and by the integrator as an implicit one, the mismatch below); and a
tendon `wheel - rotor` with friction loss max_wheel_torque, the clutch. The clutch holds
the wheel at the rotor's speed with at most max_wheel_torque, solved by MuJoCo's
constraint solver together with the contacts, as ODE solves the plugin's motor: the
stiffest MuJoCo allows (CLUTCH_SOLREF steps, CLUTCH_SOLIMP) so that it holds the speed
to ~0.01 % under load.

(A velocity actuator on the wheel itself, the earlier stand-in, needs a gain, and no gain
fits: the solver sees its force as explicit while the integrator damps it implicitly, so
above ~70 N·m·s on the course robot the soft contacts push the base up to 17 % past its
wheels' travel, and below it the wheels lag their load; tests/drive/test_drive_plugin.py.)

The wheel's effort is the clutch's torque: no MuJoCo sensor reports a friction-loss force,
so the run reads it from the rotor's constraint force (`clutch_torque`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

ROTOR_ARMATURE = 1e3  # [kg·m²] the clutch's largest torque moves it ~1e-5 rad/s in a step
CLUTCH_SOLREF = 2.0  # [steps] time constant: MuJoCo's least (it clamps below 2 dt)
CLUTCH_SOLIMP = (0.99, 0.999, 0.001, 0.5, 2.0)  # near-rigid: creep ~0.1 % of MuJoCo's default


def add_wheel_motors(ms: Any, joints: tuple[str, str], max_torque: float, dt: float) -> list[str]:
    """Add the plugin's motor (a rotor `<joint>_rotor` and its clutch) to each wheel joint.

    Any actuator the export gave a wheel joint is switched off (a note says so).
    """
    import mujoco

    notes = []
    for joint in joints:
        for act in ms.actuators:
            if act.target == joint:
                act.gainprm[0], act.biasprm[:3] = 0.0, 0.0
                notes.append(f"the export's actuator on {joint} is replaced by the plugin's motor")
        wheel = ms.joint(joint)
        body = wheel.parent
        rotor = body.parent.add_body(
            name=f"{joint}_rotor", pos=body.pos, quat=body.quat, mass=1e-6, inertia=[1e-9] * 3
        )
        rotor.add_joint(
            name=rotor.name,
            type=mujoco.mjtJoint.mjJNT_HINGE,
            pos=wheel.pos,
            axis=wheel.axis,
            armature=ROTOR_ARMATURE,
        )
        clutch = ms.add_tendon(name=f"{joint}_clutch")
        clutch.wrap_joint(joint, 1.0)
        clutch.wrap_joint(rotor.name, -1.0)
        clutch.frictionloss = max_torque
        clutch.solref_friction = [CLUTCH_SOLREF * dt, 1.0]
        clutch.solimp_friction = list(CLUTCH_SOLIMP)
    return notes


def rotor_dofs(model: Any, joints: tuple[str, str]) -> np.ndarray:
    """(2,) int: the rotors' velocity indices, for `spin` and `clutch_torque`."""
    return np.array([model.jnt_dofadr[model.joint(f"{j}_rotor").id] for j in joints], dtype=int)


def spin(data: Any, dofs: np.ndarray, speed: np.ndarray) -> None:
    """Set the rotors to the plugin's commanded joint speeds [rad/s]; before every step."""
    data.qvel[dofs] = speed


def clutch_torque(data: Any, dofs: np.ndarray) -> np.ndarray:
    """[N·m] the torque each clutch puts on its wheel in the last step.

    The rotor's only constraint is its clutch, so the wheel gets the opposite of the
    rotor's constraint force.
    """
    return -np.asarray(data.qfrc_constraint[dofs], dtype=float)
