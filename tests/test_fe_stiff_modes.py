"""The FE route keeps a mode far stiffer than the rest.

Two masses on springs 1e11 apart: inverse iteration shrinks the stiff direction
by the ratio of the eigenvalues at every sweep, and the Rayleigh–Ritz basis
must still hold it (it was dropped, and the note said only one mode exists).
Reference: the 2×2 eigenproblem in mpmath.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
from builders import fixed, make_rigid, make_spring

import linmstmm as lm

ALL_RIGID = [np.inf] * 6


def x_spring(name, a, b, k):
    """A spring of stiffness ``k`` (N/m) along x, rigid in every other direction."""
    return make_spring(name, a, b, [k] + ALL_RIGID[1:])


def two_masses(k2: float) -> lm.Model:
    """ground -1000 N/m- m1 (2 kg) -``k2``- m2 (1 kg), along x."""
    points = {"ground": np.zeros(3), "a1": np.zeros(3), "b1": np.array([1.0, 0, 0]), "a2": np.array([1.0, 0, 0])}
    rigids = (make_rigid("m1", ["a1", "b1"], 2.0, [0.5, 0, 0], [0.1, 0.1, 0.1]),
              make_rigid("m2", ["a2"], 1.0, [1.0, 0, 0], [0.1, 0.1, 0.1]))
    springs = (x_spring("k1", "ground", "a1", 1000.0), x_spring("k2", "b1", "a2", k2))
    return lm.Model("two masses", points, rigids=rigids, springs=springs, boundary={"ground": fixed()})


def test_fe_route_keeps_the_stiff_mode_of_two_masses():
    """M = diag(2, 1) kg, K = [[k1 + k2, -k2], [-k2, k2]], k1 = 1e3, k2 = 1e14 N/m:
    two modes (the FE route listed one and noted that only one exists)."""
    with mp.workdps(40):
        k2 = mp.mpf(10) ** 14
        matrix = mp.matrix([[(1000 + k2) / 2, -k2 / 2], [-k2, k2]])
        exact = sorted(float(mp.sqrt(mp.re(v)) / (2 * mp.pi)) for v in mp.eig(matrix)[0])
    result = lm.fe_frequencies(two_masses(1.0e14), count=2)
    np.testing.assert_allclose(result.frequencies_hz, exact, rtol=1e-9)
