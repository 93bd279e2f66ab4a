"""The 3-vector arithmetic of a model's checks, edits and mode shapes (linmstmm.geometry: cross3, cross_rows, norm3)
gives numpy.cross's and numpy.linalg.norm's bits, on vectors whose components span
the whole float64 range: subnormals, signed zeros, overflow to inf, and every sign."""
from __future__ import annotations

import numpy as np

from linmstmm.geometry import cross3, cross_rows, norm3


def _vectors(rng, count: int) -> np.ndarray:
    """(count, 3) components of every size and sign, some exactly 0, -0, 1 or inf."""
    vectors = rng.choice([-1.0, 1.0], (count, 3)) * 10.0 ** rng.uniform(-320, 308, (count, 3))
    mild = rng.random(count) < 0.5
    vectors[mild] = rng.standard_normal((mild.sum(), 3))
    special = rng.random((count, 3)) < 0.1
    vectors[special] = rng.choice([0.0, -0.0, 1.0, -1.0, np.inf, -np.inf], special.sum())
    return vectors


def _same(a, b) -> bool:
    """Equal bits, or both nan where nan (a nan's payload is not a number's bits)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    nan = np.isnan(a)
    return bool(np.array_equal(nan, np.isnan(b)) and a[~nan].tobytes() == b[~nan].tobytes())


def test_cross3_is_numpy_cross_bit_for_bit():
    rng = np.random.default_rng(7)
    a, b = _vectors(rng, 20000), _vectors(rng, 20000)
    with np.errstate(all="ignore"):
        for x, y in zip(a, b):
            assert _same(cross3(x, y), np.cross(x, y)), (x, y)
        for x in a[:2000]:  # a float32 partner is taken to float64 as numpy.cross takes it
            assert _same(cross3(x, x[::-1].astype(np.float32)), np.cross(x, x[::-1].astype(np.float32))), x


def test_cross_rows_is_numpy_cross_bit_for_bit():
    rng = np.random.default_rng(9)
    rows, others = _vectors(rng, 2000), _vectors(rng, 50)
    with np.errstate(all="ignore"):
        for y in others:
            assert _same(cross_rows(rows, y), np.cross(rows, y)), y


def test_norm3_is_numpy_norm_bit_for_bit():
    rng = np.random.default_rng(8)
    with np.errstate(all="ignore"):
        for x in _vectors(rng, 20000):
            assert _same(norm3(x), np.linalg.norm(x)), x
        for x in (np.array([3, 4, 12]), np.array([1.5, 2.5, 3.5], np.float32), np.array([2**62, 2**62, 1])):
            assert _same(norm3(x), np.linalg.norm(x)), x
