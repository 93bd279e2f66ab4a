"""A lone rigid body: six rigid-body modes, no elastic element, no strain energy.

Every quantity has a closed form in the body's 6 × 6 mass matrix at a point,
M_a = Tᵀ M_c T (T carries the point's motion to the mass centre's): the
mass-normalised modes at a satisfy Σ φ φᵀ = M_a⁻¹, the receptance is
−M_a⁻¹ / Ω², and a step load f gives M_a⁻¹ f t² / 2.
"""
from __future__ import annotations

import numpy as np
from builders import make_rigid

import linmstmm as lm
from linmstmm.loads import LoadCase, PointLoad, step

COM = np.array([0.05, -0.1, 0.2])
INERTIA = np.array([[0.2, 0.02, -0.01], [0.02, 0.25, 0.03], [-0.01, 0.03, 0.3]])
POINTS = {"a": np.array([0.2, 0.0, 0.0]), "b": np.array([-0.3, 0.4, 0.1])}


def lone_body() -> lm.Model:
    """A 2 kg body with a full inertia tensor and two ports, nothing else."""
    return lm.Model("lone body", dict(POINTS), rigids=(make_rigid("body", ["a", "b"], 2.0, COM, INERTIA),))


def carry(point: str) -> np.ndarray:
    """(6, 6) T: the mass centre's [u, θ] from the point's, u_c = u_p + θ × (c − p)."""
    arm = COM - POINTS[point]
    cross = np.array([[0, -arm[2], arm[1]], [arm[2], 0, -arm[0]], [-arm[1], arm[0], 0]])
    t = np.eye(6)
    t[:3, 3:] = -cross  # θ × arm = −arm × θ
    return t


def mass_at(point: str) -> np.ndarray:
    """(6, 6) the body's mass matrix for the motion of ``point``, kg and kg m (m²)."""
    central = np.zeros((6, 6))
    central[:3, :3] = 2.0 * np.eye(3)
    central[3:, 3:] = INERTIA
    t = carry(point)
    return t.T @ central @ t


def test_a_lone_rigid_body_has_six_mass_normalised_rigid_body_modes():
    body = make_rigid("body", ["a"], 2.0, np.zeros(3), [0.1, 0.2, 0.3])
    modes = lm.mode_shapes(lm.Model("free body", {"a": np.array([0.2, 0.0, 0.0])}, rigids=(body,)), count=3)
    assert modes.rigid_body_modes == 6
    np.testing.assert_allclose(modes.modal_mass, np.ones(6), rtol=1e-12)


def test_the_modes_span_the_inverse_mass_matrix_at_each_point():
    modes = lm.mode_shapes(lone_body(), count=3)
    assert modes.omega.tolist() == [0.0] * 6
    np.testing.assert_array_equal(modes.modal_stiffness, np.zeros(6))
    for point in POINTS:
        shapes = modes.point_displacements[point]  # (6 modes, 6)
        np.testing.assert_allclose(shapes.T @ shapes, np.linalg.inv(mass_at(point)), rtol=1e-10, atol=1e-12)


def test_receptance_is_the_inverse_mass_over_minus_omega_squared():
    modes = lm.mode_shapes(lone_body(), count=3)
    hz = np.array([0.5, 2.0, 7.0])
    load = np.array([1.0, -2.0, 0.5, 0.3, 0.0, -0.2])
    result = lm.frf(modes, "a", load, hz, ["a", "b"])
    for p, point in enumerate(("a", "b")):
        through = np.linalg.solve(carry(point), carry("a") @ np.linalg.solve(mass_at("a"), load))
        exact = -through[None, :] / (2 * np.pi * hz[:, None]) ** 2
        np.testing.assert_allclose(np.asarray(result.receptance)[:, p].real, exact, rtol=1e-10, atol=1e-14)


def test_step_load_accelerates_the_body_uniformly():
    force, moment = np.array([0.0, 10.0, -3.0]), np.array([1.0, 0.0, 0.5])
    times = np.linspace(0.0, 0.5, 11)
    case = LoadCase((PointLoad("a", force, moment, step()),), times, ("a", "b"), 6)
    result = lm.respond(lone_body(), case)
    acceleration_a = np.linalg.solve(mass_at("a"), np.r_[force, moment])
    for p, point in enumerate(("a", "b")):
        accel = np.linalg.solve(carry(point), carry("a") @ acceleration_a)
        exact = 0.5 * times[:, None] ** 2 * accel[None, :]
        np.testing.assert_allclose(np.asarray(result.displacement)[:, p], exact, rtol=1e-10, atol=1e-14)
