"""det Ū_all over the blocks of its lone columns and the rest
(:func:`linmstmm._assembly_kernels.determinant_blocks`), against the LU of the
whole matrix: numpy's slogdet, which knows nothing of the blocks.

A column of Ū_all with one entry that can be nonzero expands the determinant
along itself (Laplace); the layout takes such columns one after another and the
rest as one block, with the sign of the permutations that bring them to the
diagonal. The random patterns below plant lone columns, some of which stand
alone only once another has taken its row, and scatter them by random
permutations, so that every sign is met.
"""
from __future__ import annotations

import mpmath
import numpy as np
import pytest

from linmstmm import _kernels
from linmstmm._assembly_kernels import determinant_blocks
from linmstmm.deduction import Deduction
from linmstmm.determinant import CompiledDeterminant
from linmstmm.model import load_model
from linmstmm.nullspace import release_indeterminate
from linmstmm.topology import build_topology


def planted(rng, n: int, lone: int, chained: int) -> np.ndarray:
    """(n, n) pattern (bool): ``lone`` columns with one entry, ``chained`` more whose other
    entries lie on the rows of those before them, a dense rest; rows and columns
    permuted at random."""
    pattern = np.zeros((n, n), dtype=bool)
    taken = lone + chained
    for k in range(taken):
        pattern[k, k] = True
        if k >= lone:  # entries on rows taken before: alone once those are
            pattern[rng.choice(k, size=min(k, 2), replace=False), k] = True
        pattern[k, taken:] = rng.random(n - taken) < 0.5  # its row reaches the rest
    pattern[taken:, taken:] = rng.random((n - taken, n - taken)) < 0.7
    pattern[taken:, taken:] |= np.eye(n - taken, dtype=bool)
    return pattern[np.ix_(rng.permutation(n), rng.permutation(n))]


def blocks_log_det(values: np.ndarray, pattern: np.ndarray, dtype) -> tuple:
    """(sign, log|det|) of the matrix holding ``values`` (n, n) on ``pattern``, by the
    compiled kernel over :func:`determinant_blocks`' layout; and the layout's block orders."""
    n = pattern.shape[0]
    rows, columns = np.nonzero(pattern)
    targets = (columns * n + rows).astype(np.int64)
    workspace = values[rows, columns].astype(dtype)
    sources = np.arange(targets.size, dtype=np.int64)
    block_sources, block_targets, offsets, orders, sign = determinant_blocks(sources, targets, n)
    blocks = np.empty(offsets[-1], dtype=dtype)
    found = _kernels._block_log_det(workspace, block_sources, block_targets, blocks, offsets, orders, sign)
    return found, orders


@pytest.mark.parametrize("dtype", [float, complex])
@pytest.mark.parametrize("seed", range(12))
def test_the_blocks_give_the_whole_determinant(seed, dtype):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 40))
    lone = int(rng.integers(0, n // 3 + 1))
    chained = int(rng.integers(0, n // 4 + 1))
    pattern = planted(rng, n, lone, chained)
    values = rng.standard_normal((n, n)) + (1j * rng.standard_normal((n, n)) if dtype == complex else 0)
    values = np.where(pattern, values, 0)
    (sign, log_abs), orders = blocks_log_det(values, pattern, dtype)
    expected_sign, expected_log = np.linalg.slogdet(values)
    assert np.sum(orders == 1) >= lone + chained  # every planted column found alone
    assert orders.sum() == n
    assert abs(sign - expected_sign) < 1e-12
    assert log_abs == pytest.approx(expected_log, rel=1e-12, abs=1e-12)


def test_without_lone_columns_the_layout_is_the_matrix_itself():
    """One block, Ū_all's own entries in its own places: the LU of before, to the bit."""
    n = 9
    rows, columns = np.nonzero(np.ones((n, n), dtype=bool))
    targets = (columns * n + rows).astype(np.int64)
    sources = np.arange(targets.size, dtype=np.int64)
    block_sources, block_targets, offsets, orders, sign = determinant_blocks(sources, targets, n)
    assert orders.tolist() == [n] and sign == 1.0 and offsets.tolist() == [0, n * n]
    assert np.array_equal(block_sources, sources) and np.array_equal(block_targets, targets)


def test_a_lone_entry_at_zero_makes_the_determinant_zero():
    pattern = np.ones((5, 5), dtype=bool)
    pattern[1:, 2] = False  # column 2 alone at row 0
    values = np.arange(1.0, 26.0).reshape(5, 5) ** 1.5
    values[0, 2] = 0.0
    (sign, log_abs), orders = blocks_log_det(np.where(pattern, values, 0), pattern, float)
    assert (sign, log_abs) == (0.0, -np.inf) and orders.tolist() == [1, 4]
    values[3, 3] = np.nan
    (sign, log_abs), _ = blocks_log_det(np.where(pattern, values, 0), pattern, float)
    assert np.isnan(sign) and np.isnan(log_abs)


def exact_log_det(matrix: np.ndarray) -> tuple[complex, float]:
    """(sign or phase, log|det|) of the float ``matrix`` itself, in mpmath at 40 digits."""
    with mpmath.workdps(40):
        det = mpmath.det(mpmath.matrix([[mpmath.mpc(complex(v)) for v in row] for row in matrix]))
        return complex(det / abs(det)), float(mpmath.log(abs(det)))


@pytest.mark.parametrize("path, order", [("models/mlrs/mlrs.toml", 60), ("models/launcher2/launcher2.toml", 72)])
def test_the_root_unknowns_stand_alone_and_the_determinant_is_exact(path, order):
    """The launchers' clamped root: its six unknown forces enter Ū_all through the root's
    selection alone, six lone columns. The compiled log|det Ū_all| is that of the whole
    orthonormalised Ū_all the same kernels return (its log-scale added), computed
    exactly in mpmath. (On launcher 2 at 410 rad/s the LU of the whole matrix is
    2.2e-10 off that; the blocks' 1.6e-12.)"""
    deduction = Deduction(build_topology(load_model(path)))
    release_indeterminate(deduction)
    compiled = CompiledDeterminant(deduction)
    assert compiled.program.block_orders.tolist() == [1] * 6 + [order - 6]
    omega = np.array([7.3, 410.0, 2100.0 * (1 + 0.01j)])
    sign, log_abs = compiled.log_det(omega)
    for k in range(omega.size):
        matrix, log_scale = compiled.matrix(omega[k:k + 1])
        exact_sign, exact_log = exact_log_det(matrix[0])
        assert log_abs[k] == pytest.approx(exact_log + log_scale[0], rel=1e-12)
        assert abs(sign[k] - exact_sign) < 1e-9
