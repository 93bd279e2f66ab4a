"""Element-level properties that need no reference solution."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from builders import make_beam
from scipy.spatial.transform import Rotation

import linmstmm.elements.beam as beam_module
from linmstmm.elements.beam import beam_states, beam_transfer
from linmstmm.elements.frames import SYMPLECTIC_FORM, state_rotation
from linmstmm.elements.rigid import rigid_transfer
from linmstmm.elements.spring import spring_transfer

OMEGA = np.array([0.0, 3.0, 170.0, 2500.0, 2.0e4])
ROTATION = Rotation.from_euler("zyx", [0.4, -0.7, 1.1]).as_matrix()
INERTIA = np.array([[4.0, 0.3, -0.2], [0.3, 5.0, 0.1], [-0.2, 0.1, 6.0]])


def energy_form_residual(U):
    """max |UᵀJU − J| relative to |U|² (per frequency)."""
    residual = np.abs(np.swapaxes(U, 1, 2) @ SYMPLECTIC_FORM @ U - SYMPLECTIC_FORM).max(axis=(1, 2))
    return residual / np.abs(U).max(axis=(1, 2)) ** 2


def a_beam(axes_points=((0.0, 0.0, 0.0), (1.2, 0.5, -0.3)), **options):
    points = {"a": np.array(axes_points[0]), "b": np.array(axes_points[1])}
    return make_beam("b", "a", "b", points, Iy=3e-7, Iz=5e-7, J=6e-7, **options)


def spring_axes():
    return ROTATION.T  # rows: a rotated orthonormal triad


ELEMENTS = {
    "spring": lambda: spring_transfer([1e6, 2e6, 3e5, 4e4, 5e3, 6e4], spring_axes(), OMEGA),
    "spring with rigid directions": lambda: spring_transfer([1e6, np.inf, 3e5, np.inf, 5e3, 6e4],
                                                            spring_axes(), OMEGA),
    "rigid": lambda: rigid_transfer(12.0, [0.3, -0.2, 0.5], INERTIA, [0.0, 0.1, 0.0], [1.0, 0.4, -0.6], OMEGA),
    "beam": lambda: beam_transfer(a_beam(), OMEGA),
    "beam reversed": lambda: beam_transfer(a_beam(), OMEGA, reverse=True),
    "beam rigid axial and torsion": lambda: beam_transfer(a_beam(axial=False, torsion=False), OMEGA),
}


@pytest.mark.parametrize("name", sorted(ELEMENTS))
def test_conservative_elements_keep_the_energy_form(name):
    assert energy_form_residual(ELEMENTS[name]()).max() < 1e-13


def test_beam_of_length_L_is_two_halves_multiplied():
    beam = a_beam()
    half = beam_transfer(beam, OMEGA, length=beam.length / 2)
    whole = beam_transfer(beam, OMEGA)
    scale = np.abs(whole).max(axis=(1, 2), keepdims=True)
    assert (np.abs(half @ half - whole) / scale).max() < 1e-13


@pytest.mark.parametrize("batch", [10_000, 7])  # one evaluation, or distances in several
def test_beam_states_are_each_piece_transferred(batch, monkeypatch):
    """beam_states (every distance and frequency in one evaluation) against beam_transfer of
    each piece alone, both directions."""
    monkeypatch.setattr(beam_module, "STATES_BATCH", batch)
    beam = a_beam()
    start = np.random.default_rng(3).standard_normal((OMEGA.size, 12))
    distances = np.array([0.0, 0.1, 0.5, 0.77, 1.0]) * beam.length
    for reverse in (False, True):
        got = beam_states(beam, OMEGA, start, distances, reverse)
        for s, distance in enumerate(distances):
            want = start if distance == 0 else np.einsum(
                "nij,nj->ni", beam_transfer(beam, OMEGA, reverse=reverse, length=distance), start)
            scale = np.abs(want).max(axis=1, keepdims=True)
            assert (np.abs(got[:, s] - want) / scale).max() < 1e-13


def test_beam_matches_matrix_exponential_of_its_state_equation():
    """exp(A L) by scipy (Padé) against the closed form, local axes along x."""
    points = {"a": np.zeros(3), "b": np.array([1.7, 0.0, 0.0])}
    beam = make_beam("b", "a", "b", points, Iy=3e-7, Iz=5e-7, J=6e-7, Ip=9e-7)
    EA, GJ, rhoA = beam.E * beam.A, beam.G * beam.J, beam.rho * beam.A
    for omega in (0.0, 40.0, 900.0):
        A = np.zeros((12, 12))
        A[0, 9], A[9, 0] = -1 / EA, rhoA * omega**2
        A[3, 6], A[6, 3] = -1 / GJ, beam.rho * beam.Ip * omega**2
        A[1, 5], A[5, 8], A[8, 10], A[10, 1] = 1, -1 / (beam.E * beam.Iz), -1, rhoA * omega**2
        A[2, 4], A[4, 7], A[7, 11], A[11, 2] = -1, -1 / (beam.E * beam.Iy), 1, rhoA * omega**2
        expected = scipy.linalg.expm(A * beam.length)
        got = beam_transfer(beam, np.array([omega]))[0]
        assert np.abs(got - expected).max() / np.abs(expected).max() < 1e-13


def test_reversed_beam_is_the_inverse_with_forces_turned_round():
    beam = a_beam()
    flip = np.diag(np.r_[np.ones(6), -np.ones(6)])
    forward, backward = beam_transfer(beam, OMEGA), beam_transfer(beam, OMEGA, reverse=True)
    product = flip @ backward @ flip @ forward
    scale = np.abs(backward).max(axis=(1, 2)) * np.abs(forward).max(axis=(1, 2))
    assert (np.abs(product - np.eye(12)).max(axis=(1, 2)) / scale).max() < 1e-14


def test_rotated_elements_equal_the_rotation_applied():
    T = state_rotation(ROTATION.T)  # maps components in the unrotated frame to the rotated one
    inp, out, com = np.array([0.0, 0.1, 0.0]), np.array([1.0, 0.4, -0.6]), np.array([0.3, -0.2, 0.5])
    plain = rigid_transfer(12.0, com, INERTIA, inp, out, OMEGA)
    turned = rigid_transfer(12.0, ROTATION @ com, ROTATION @ INERTIA @ ROTATION.T,
                            ROTATION @ inp, ROTATION @ out, OMEGA)
    assert np.abs(turned - T @ plain @ T.T).max() < 1e-9 * np.abs(plain).max()

    k = [1e6, 2e6, 3e5, 4e4, 5e3, 6e4]
    plain = spring_transfer(k, np.eye(3), OMEGA)
    turned = spring_transfer(k, (ROTATION @ np.eye(3)).T, OMEGA)
    assert np.abs(turned - T @ plain @ T.T).max() < 1e-12 * np.abs(plain).max()

    a, b = np.array([0.0, 0.0, 0.0]), np.array([1.2, 0.5, -0.3])
    plain_beam = a_beam((a, b))
    turned_beam = make_beam("b", "a", "b", {"a": ROTATION @ a, "b": ROTATION @ b}, Iy=3e-7, Iz=5e-7,
                            J=6e-7, y_hint=ROTATION @ plain_beam.axes[1])
    plain = beam_transfer(plain_beam, OMEGA)
    assert np.abs(beam_transfer(turned_beam, OMEGA) - T @ plain @ T.T).max() < 1e-12 * np.abs(plain).max()


def test_infinite_stiffness_is_the_limit_of_large_stiffness():
    k = np.array([1e6, np.inf, 3e5, np.inf, 5e3, 6e4])
    rigid = spring_transfer(k, spring_axes(), OMEGA)
    for large in (1e12, 1e15):
        stiff = spring_transfer(np.where(np.isinf(k), large, k), spring_axes(), OMEGA)
        assert np.abs(stiff - rigid).max() < 10 / large


def test_rigid_axial_and_torsion_are_the_limit_of_large_stiffness():
    points = {"a": np.zeros(3), "b": np.array([1.5, 0.0, 0.0])}
    rigid = beam_transfer(make_beam("b", "a", "b", points, axial=False, torsion=False), OMEGA)
    # Raise EA and GJ through A·E and J only in the axial/torsion blocks: scale E and G, then
    # undo the bending change by scaling the second moments back.
    scale = 1e8
    material = {"E": 2.1e11 * scale, "G": 8.1e10 * scale, "rho": 7850.0}
    stiff = beam_transfer(make_beam("b", "a", "b", points, Iy=2e-7 / scale, Iz=2e-7 / scale,
                                    Ip=4e-7, material=material), OMEGA)
    axial_torsion = np.ix_(range(OMEGA.size), [0, 3, 6, 9], [0, 3, 6, 9])
    difference = np.abs(stiff[axial_torsion] - rigid[axial_torsion]).max(axis=(1, 2))
    assert (difference / np.abs(rigid[axial_torsion]).max(axis=(1, 2))).max() < 1e-6
