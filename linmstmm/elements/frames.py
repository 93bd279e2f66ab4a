"""Geometric helpers shared by the element modules.

State index blocks: ``U`` displacement 0:3, ``R`` rotation 3:6, ``M`` moment
6:9, ``Q`` force 9:12.
"""
from __future__ import annotations

import numpy as np

from linmstmm.numeric import number_type

U, R, M, Q = slice(0, 3), slice(3, 6), slice(6, 9), slice(9, 12)

#: Index of the internal force/moment paired (by work) with displacement
#: component 0..5 (x, y, z, rx, ry, rz): X-Qx, ..., Θz-Mz.
FORCE_INDEX = np.array([9, 10, 11, 6, 7, 8])

#: Energy pairing of the state: Zᵀ J Z' = d·f' − f·d' with d = (u, θ) paired
#: with f = (q, m). A conservative element's transfer matrix keeps it:
#: Uᵀ J U = J.
SYMPLECTIC_FORM = np.zeros((12, 12))
SYMPLECTIC_FORM[np.arange(6), FORCE_INDEX] = 1.0
SYMPLECTIC_FORM[FORCE_INDEX, np.arange(6)] = -1.0


def skew(r) -> np.ndarray:
    """(..., 3, 3) cross-product matrices of (..., 3) vectors: ``skew(r) @ v == np.cross(r, v)``.

    r : float, or mpmath numbers (then an object array, its zeros the float 0.0).
    """
    r = np.asarray(r)
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    out = np.zeros(r.shape[:-1] + (3, 3)).astype(number_type(r), copy=False)
    out[..., 0, 1], out[..., 0, 2] = -z, y
    out[..., 1, 0], out[..., 1, 2] = z, -x
    out[..., 2, 0], out[..., 2, 1] = -y, x
    return out


def identities(shape: tuple, rows: int, columns: int | None = None, dtype=np.float64) -> np.ndarray:
    """(*shape, rows, columns) matrices of ``dtype`` (columns = rows if None, rows ≤ columns),
    each :func:`numpy.eye` (ones on the diagonal, zeros elsewhere); writable."""
    columns = rows if columns is None else columns
    out = np.zeros(shape + (rows, columns), dtype=dtype)
    out.reshape(shape + (rows * columns,))[..., ::columns + 1] = 1  # the diagonal of each
    return out


def state_rotation(axes) -> np.ndarray:
    """(12, 12) map from local to inertial state components.

    ``axes`` rows are the local x, y, z unit vectors in the inertial frame, so
    a local vector v maps to ``axes.T @ v`` in the inertial frame.
    """
    return np.kron(np.eye(4), np.asarray(axes, dtype=float).T)
