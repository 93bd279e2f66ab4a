"""The modal receptance with the residual flexibility of the modes left out,
against closed forms: a massless point between two springs (no mode holds its
flexibility), a cantilever's axial tip receptance below its first axial mode
(no axial mode in the sum), and its bending tip receptance (Blevins)."""
from __future__ import annotations

import numpy as np
from builders import fixed, make_beam, make_rigid, make_spring

import linmstmm as lm
from linmstmm.fe import static_displacements
from linmstmm.studies import frf_study

RIGID = [np.inf] * 6
STEEL_ROD = dict(material=dict(E=2.0e11, G=8.0e10, rho=7800.0), A=1.0e-3, Iy=3.0e-7, J=2.0e-7, Ip=4.2e-7)


def x_spring(name, a, b, k):
    """A spring of stiffness ``k`` (N/m) along x, rigid in every other direction."""
    return make_spring(name, a, b, [k] + RIGID[1:])


def cantilever() -> lm.Model:
    """A 1.5 m steel rod clamped at "root", Iz = 1.2e-7 m⁴."""
    points = {"root": np.zeros(3), "tip": np.array([1.5, 0.0, 0.0])}
    return lm.Model("cantilever", points, beams=(make_beam("b", "root", "tip", points, Iz=1.2e-7, **STEEL_ROD),),
                    boundary={"root": fixed()})


def test_a_massless_point_between_two_springs_is_exact_with_its_static_flexibility():
    """x at p of ground -k1 (1000 N/m)- p -k2 (500 N/m)- m (2 kg):
    H = [[k1 + k2, −k2], [−k2, k2 − m ω²]]⁻¹ at p. The model's one mode is in the
    sum; the modal sum alone gave 0.44e-3 m/N at 0.5 Hz against 1.10e-3."""
    points = {name: np.zeros(3) for name in ("ground", "p", "q")}
    model = lm.Model("mass behind two springs in series", points,
                     rigids=(make_rigid("m", ["q"], 2.0, np.zeros(3), [0.1, 0.1, 0.1]),),
                     springs=(x_spring("k1", "ground", "p", 1000.0), x_spring("k2", "p", "q", 500.0)),
                     boundary={"ground": fixed()})
    unit = np.eye(6)[0]
    modes = lm.mode_shapes(model, count=5)
    hz = np.array([0.5, 1.0, 3.0, 4.0])
    static = static_displacements(model, [("p", unit)], ["p"])[0]
    result = lm.frf(modes, "p", unit, hz, ["p"], static=static)
    omega2 = (2 * np.pi * hz) ** 2
    exact = (500.0 - 2.0 * omega2) / (1500.0 * (500.0 - 2.0 * omega2) - 500.0**2)
    np.testing.assert_allclose(result.receptance[:, 0, 0].real, exact, rtol=1e-9)


def test_the_axial_tip_receptance_below_the_first_axial_mode():
    """tan(kL) / (EA k), k = ω √(ρ/E). The sum holds bending modes only (up to twice
    fmax), so without the correction it was 1e-69 m/N against 7.5e-9; with it the
    error is that of a quasi-static axial rod, about (f / f_axial)²."""
    result, summary = frf_study(cantilever(), "tip", "x", 100.0, frequencies=10)
    assert summary["static_correction"]
    hz = result.excitation_hz
    k = 2 * np.pi * hz * np.sqrt(7800.0 / 2.0e11)
    exact = np.tan(k * 1.5) / (2.0e11 * 1.0e-3 * k)
    first_axial_hz = np.sqrt(2.0e11 / 7800.0) / (4 * 1.5)
    assert np.all(np.abs(result.receptance[:, 0, 0].real / exact - 1) <= 2 * (hz / first_axial_hz) ** 2)


def test_the_bending_tip_receptance_is_ten_times_closer_with_the_correction():
    """Blevins' tip receptance of a cantilever, (sin x cosh x − cos x sinh x) /
    (EI β³ (1 + cos x cosh x)), x = βL, up to 200 Hz: the error relative to the
    static receptance falls from 1.4e-3 (the modal sum up to 400 Hz) to 1.8e-4."""
    model = cantilever()
    result, _ = frf_study(model, "tip", "y", 200.0, frequencies=40)
    EI, rho_A = 2.0e11 * 1.2e-7, 7800.0 * 1.0e-3
    beta = (rho_A * (2 * np.pi * result.excitation_hz) ** 2 / EI) ** 0.25
    x = 1.5 * beta
    exact = (np.sin(x) * np.cosh(x) - np.cos(x) * np.sinh(x)) / (EI * beta**3 * (1 + np.cos(x) * np.cosh(x)))
    static = 1.5**3 / (3 * EI)
    corrected = np.max(np.abs(result.receptance[:, 0, 1].real - exact)) / static
    plain = lm.frf(lm.mode_shapes(model, None, fmax=400.0), "tip", np.eye(6)[1], result.excitation_hz, ["tip"])
    uncorrected = np.max(np.abs(plain.receptance[:, 0, 1].real - exact)) / static
    assert corrected <= 3e-4 and corrected * 5 <= uncorrected
