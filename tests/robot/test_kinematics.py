"""armcli.robot.kinematics through `Robot`'s methods, against closed forms, finite
differences and energies computed another way."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from armcli.errors import InputError
from armcli.robot.model import Robot
from armcli.urdf.read import parse_urdf
from tests.robot.test_model import URDF

EXACT = 1e-12  # the same products in another order
H = 1e-6  # [rad or m] central-difference step
FD_TOL = 1e-8  # central differences: O(H²) truncation plus round-off of ~1e-16 / H
VALUES = {"yaw": 2.0, "pitch": 0.5, "slide": 0.2, "grip": 0.04}


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.load(parse_urdf(URDF, "t.urdf"))


def Rz(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def Ry(a: float) -> np.ndarray:
    return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])


def _moved(robot: Robot, name: str, h: float) -> np.ndarray:
    return robot.q({**VALUES, name: VALUES[name] + h})


def _derivative(robot: Robot, f, name: str) -> np.ndarray:
    """d f(q) / d (joint `name`) by central differences (a continuous joint by its angle)."""
    return (f(_moved(robot, name, H)) - f(_moved(robot, name, -H))) / (2 * H)


def test_frame_pose_and_tool_position_are_the_closed_form(robot: Robot) -> None:
    """The URDF's chain: yaw about z at 0.1, pitch about y 0.2 higher, the slider 0.5 + s
    along the arm's x, the flange (the tool point) 0.1 further."""
    yaw, pitch, s = VALUES["yaw"], VALUES["pitch"], VALUES["slide"]
    q = robot.q(VALUES)
    T = robot.frame_pose("arm", q)
    np.testing.assert_allclose(T[:3, :3], Rz(yaw) @ Ry(pitch), atol=EXACT)
    np.testing.assert_allclose(T[:3, 3], [0, 0, 0.3], atol=EXACT)
    flange = Rz(yaw) @ np.array([0, 0, 0.3]) + Rz(yaw) @ Ry(pitch) @ np.array([0.6 + s, 0, 0])
    np.testing.assert_allclose(robot.tool_position(q), flange, atol=EXACT)
    offset = np.array([0.0, 0.02, -0.03])
    point = flange + Rz(yaw) @ Ry(pitch) @ offset
    np.testing.assert_allclose(robot.point_position("flange", offset, q), point, atol=EXACT)


def test_jacobian_is_the_derivative_of_the_point(robot: Robot) -> None:
    offset = np.array([0.05, -0.02, 0.01])
    q = robot.q(VALUES)
    p, J = robot.jacobian(q, "slider", offset)
    np.testing.assert_allclose(p, robot.point_position("slider", offset, q), atol=EXACT)
    for name in robot.names:
        column = J[:3, robot.joint(name).idx_v]
        fd = _derivative(robot, lambda q: robot.point_position("slider", offset, q), name)
        np.testing.assert_allclose(column, fd, atol=FD_TOL, err_msg=name)
    # the angular rows: z for yaw, the turned y axis for pitch, nothing for the slides
    turned_y = Rz(VALUES["yaw"]) @ np.array([0.0, 1.0, 0.0])
    axes = np.array([[0.0, 0.0, 1.0], turned_y, np.zeros(3), np.zeros(3)])
    np.testing.assert_allclose(J[3:].T, axes, atol=EXACT)
    tool_p, tool_J = robot.jacobian(q)  # the tool point by default: the flange's origin
    np.testing.assert_allclose(tool_p, robot.tool_position(q), atol=EXACT)
    _, cols = robot.jacobian(q, columns=[1, 2])
    np.testing.assert_array_equal(cols, tool_J[:, [1, 2]])


def test_mass_matrix_gives_the_kinetic_energy(robot: Robot) -> None:
    """½ vᵀ M v against Pinocchio's kinetic energy (its forward pass, not CRBA)."""
    q = robot.q(VALUES)
    M = robot.mass_matrix(q)
    np.testing.assert_array_equal(M, M.T)
    rng = np.random.default_rng(1)
    for v in rng.normal(size=(5, robot.model.nv)):
        energy = pin.computeKineticEnergy(robot.model, pin.Data(robot.model), q, v)
        assert 0.5 * v @ M @ v == pytest.approx(energy, rel=1e-12)


def test_gravity_is_the_gradient_of_the_potential_and_its_stiffness_its_slope(
    robot: Robot,
) -> None:
    q = robot.q(VALUES)

    def potential(q: np.ndarray) -> float:
        return float(pin.computePotentialEnergy(robot.model, pin.Data(robot.model), q))

    g = robot.gravity(q)
    slope = np.zeros((robot.model.nv, robot.model.nv))
    for name in robot.names:
        i = robot.joint(name).idx_v
        assert g[i] == pytest.approx(_derivative(robot, potential, name), abs=FD_TOL)
        slope[:, i] = _derivative(robot, robot.gravity, name)
    np.testing.assert_allclose(robot.gravity_jacobian(q), slope, atol=1e-7)
    np.testing.assert_allclose(robot.gravity_stiffness(q), 0.5 * (slope + slope.T), atol=1e-7)


def test_inverse_dynamics_is_mass_matrix_gravity_and_the_energy_balance(robot: Robot) -> None:
    """RNEA against CRBA: tau(q, 0, a) = M a + g; the velocity terms do no work beyond
    the mass matrix's change: vᵀ (tau(q, v, 0) - g) = ½ vᵀ (dM/dt) v (M by central
    differences along v)."""
    q = robot.q(VALUES)
    rng = np.random.default_rng(2)
    zero = np.zeros(robot.model.nv)
    for v, a in rng.normal(size=(4, 2, robot.model.nv)):
        expected = robot.mass_matrix(q) @ a + robot.gravity(q)
        np.testing.assert_allclose(robot.inverse_dynamics(q, zero, a), expected, atol=1e-12)
        M_dot = (robot.mass_matrix(pin.integrate(robot.model, q, H * v))
                 - robot.mass_matrix(pin.integrate(robot.model, q, -H * v))) / (2 * H)  # fmt: skip
        work = v @ (robot.inverse_dynamics(q, v, zero) - robot.gravity(q))
        assert work == pytest.approx(0.5 * v @ M_dot @ v, abs=FD_TOL)


def test_center_of_mass_weighs_the_bodies(robot: Robot) -> None:
    """The URDF's bodies: 1 kg at the turret's and slider's origins, 1 kg 0.25 m along the
    arm, 0.1 kg at the finger."""
    q = robot.q(VALUES)
    parts = [
        (1.0, "turret", (0.0, 0.0, 0.0)),
        (1.0, "arm", (0.25, 0.0, 0.0)),
        (1.0, "slider", (0.0, 0.0, 0.0)),
        (0.1, "finger", (0.0, 0.0, 0.0)),
    ]
    expected = sum(m * robot.point_position(link, xyz, q) for m, link, xyz in parts) / 3.1
    np.testing.assert_allclose(robot.center_of_mass(q), expected, atol=EXACT)
    c, J = robot.center_of_mass_jacobian(q)
    np.testing.assert_allclose(c, expected, atol=EXACT)
    for name in robot.names:
        fd = _derivative(robot, robot.center_of_mass, name)
        np.testing.assert_allclose(J[:, robot.joint(name).idx_v], fd, atol=FD_TOL)


def test_a_robot_without_a_tool_point_says_so(robot: Robot) -> None:
    with pytest.raises(InputError, match="no link to use as the tool point"):
        Robot(robot.model).tool_position(robot.neutral())
