"""The compiled bracketing of a tridiagonal matrix's lowest eigenvalues to an accuracy
asked for (linmstmm._tridiagonal_kernels.lowest_values), checked against LAPACK's
eigenvalues of the same matrix (scipy.linalg.eigvalsh_tridiagonal, stebz), which share
nothing with it but the matrix; and the Bisection that takes its values, whose
vectors stay syevx's."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from linmstmm._tridiagonal_kernels import lowest_values
from linmstmm.coarse_prediction import coarse_pencil
from linmstmm.standard_eigen import Bisection
from linmstmm.model import load_model

EPS = np.finfo(float).eps


def lowest(diagonal, off_diagonal, count, relative_width):
    out = np.empty(count)
    lowest_values(diagonal, off_diagonal, count, relative_width, out)
    return out


def allowed(expected, diagonal, off_diagonal, relative_width):
    """Half a bracket's width, plus LAPACK's own and the brackets' floor, 4 ε ‖T‖ each."""
    norm = np.max(np.abs(diagonal)) + 2 * np.max(np.abs(off_diagonal), initial=0.0)
    return 0.5 * relative_width * np.abs(expected) * (1 + relative_width) + 8 * EPS * norm


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("relative_width", [1e-3, 1e-7, 0.0])
def test_random_matrices_eigenvalues_within_the_width_asked(seed, relative_width):
    """Sizes 1 to 60, entries spread over ten decades (a stiff pencil's standard form spans
    several), any count: each value within half its bracket of LAPACK's, plus rounding."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 61))
    diagonal = 10.0 ** rng.uniform(-5, 5, n) * rng.choice([-1, 1], n, p=[0.2, 0.8])
    off_diagonal = 10.0 ** rng.uniform(-5, 4, n - 1) * rng.choice([-1, 1], n - 1)
    count = int(rng.integers(1, n + 1))
    expected = scipy.linalg.eigvalsh_tridiagonal(diagonal, off_diagonal, select="i", select_range=(0, count - 1))
    found = lowest(diagonal, off_diagonal, count, relative_width)
    assert np.all(np.diff(found) >= 0)
    assert np.all(np.abs(found - expected) <= allowed(expected, diagonal, off_diagonal, relative_width))


def test_equal_eigenvalues_come_out_equal():
    """Two identical blocks (a symmetric structure's standard form splits so): each double
    eigenvalue's brackets never part, so its two values are the same number, as stebz
    gives them (MRRR gave the tip-mass cantilever's pair 1e-9 apart)."""
    rng = np.random.default_rng(5)
    block_diagonal, block_off = rng.uniform(1, 10, 7), rng.uniform(-2, 2, 6)
    diagonal = np.r_[block_diagonal, block_diagonal]
    off_diagonal = np.r_[block_off, 0.0, block_off]
    found = lowest(diagonal, off_diagonal, 10, 1e-6)
    assert np.array_equal(found[0::2], found[1::2])
    expected = scipy.linalg.eigvalsh_tridiagonal(block_diagonal, block_off)[:5]
    assert np.all(np.abs(found[0::2] - expected) <= allowed(expected, diagonal, off_diagonal, 1e-6))


@pytest.mark.parametrize("unit", [1e-9, 1.0, 1e9])
def test_the_accuracy_is_relative_whatever_the_units(unit):
    """The same matrix in other units: the same relative accuracy of every value."""
    rng = np.random.default_rng(3)
    diagonal, off_diagonal = rng.uniform(0.5, 20, 30), rng.uniform(-1, 1, 29)
    expected = scipy.linalg.eigvalsh_tridiagonal(diagonal, off_diagonal)[:8]
    found = lowest(unit * diagonal, unit * off_diagonal, 8, 1e-8) / unit
    assert np.all(np.abs(found / expected - 1) <= 0.5e-8 * (1 + 1e-8) + 1e-14)


def test_a_matrix_not_finite_gives_values_not_finite():
    """It ends, and says so in its values, rather than bracketing forever."""
    for bad in (np.nan, np.inf, -np.inf):
        diagonal, off_diagonal = np.array([1.0, bad, 3.0]), np.array([0.5, 0.5])
        assert not np.any(np.isfinite(lowest(diagonal, off_diagonal, 2, 1e-6)))
        assert not np.any(np.isfinite(lowest(off_diagonal[[0, 1, 0]], diagonal[:2], 2, 1e-6)))


@pytest.mark.parametrize("path, count", [("models/mlrs/mlrs.toml", 13), ("models/cantilever_tip_mass.toml", 16)])
def test_a_bisection_to_an_accuracy_keeps_syevx_vectors(path, count):
    """The launcher's and the cantilever's coarse standard forms: values within the
    accuracy of syevx's (stebz's to rounding), and vectors syevx's to the bit, made of
    syevx's own values (found when the vectors are asked for)."""
    reduced = coarse_pencil(load_model(path), 2).reduced
    count = min(count, reduced.shape[0] - 1)
    exact = Bisection(reduced, count)
    loose = Bisection(reduced, count, accuracy=1e-7)
    assert np.all(np.abs(loose.values / exact.values - 1) <= 1e-7)
    assert not np.array_equal(loose.values, exact.values)  # to the accuracy asked, not to rounding
    assert np.array_equal(loose.vectors(), exact.vectors())
