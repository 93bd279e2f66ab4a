"""Static condensation of the massless DOFs (exact: they have no inertia): the
mass factor ``M = B Bᵀ`` and all elastic modes of a small model from the
condensed flexibility ``Bᵀ K⁺ B``."""
from __future__ import annotations

import numpy as np
import scipy.linalg as la

from linmstmm.fe.assembly import FEModel

#: Eigenvalues of the mass matrix scaled to unit diagonal below this fraction of
#: the largest are the rounding of an exact zero: directions without mass.
MASS_RANK = 1e-12
#: Modes whose operator eigenvalue 1/λ is below this fraction of the largest
#: are beyond float64 resolution and treated as infinitely stiff.
UNRESOLVED_STIFFNESS = 1e-13


def _mass_factor(fe: FEModel) -> np.ndarray:
    """(n_dof, r) B with ``M = B Bᵀ``, r = rank M: the directions that carry mass.

    Only the massive DOFs enter. Their block of M is scaled to unit diagonal, so
    that translations (kg) and rotations (kg m²) weigh alike whatever the units;
    its eigenvalues below MASS_RANK of the largest are the rounding of exact zeros
    (directions without mass across DOFs, as of a singular inertia tensor in skew
    axes) and are left out.
    """
    block = fe.M[fe.massive][:, fe.massive].toarray()
    size = np.sqrt(block.diagonal())
    values, vectors = la.eigh(block / np.outer(size, size))
    kept = values > MASS_RANK * values.max(initial=0.0)
    factor = np.zeros((fe.n_dof, np.count_nonzero(kept)))
    factor[fe.massive] = size[:, None] * vectors[:, kept] * np.sqrt(values[kept])
    return factor


def _dense_start(fe: FEModel, flexibility) -> np.ndarray:
    """All resolvable elastic modes of a small model, approximately, softest first.

    Static condensation of the massless DOFs, which is exact (they have no
    inertia): with ``M = B Bᵀ`` (:func:`_mass_factor`) the condensed flexibility
    ``Bᵀ K⁺ B`` (r x r) has eigenvalues 1/λ for the elastic modes and 0 for the
    rigid-body modes, and a mode is ``x = K⁺ B z λ``, its massless DOFs
    following statically. There are exactly r − (rigid-body modes) elastic
    modes, so no eigenvalue of a massless direction is ever mistaken for one.
    """
    factor = _mass_factor(fe)
    elastic = factor.shape[1] - fe.rigid_modes.shape[1]
    if elastic <= 0:
        return np.zeros((fe.n_dof, 0))
    flexible = flexibility(factor)
    condensed = factor.T @ flexible
    theta, Z = la.eigh(0.5 * (condensed + condensed.T))
    theta, Z = theta[::-1][:elastic], Z[:, ::-1][:, :elastic]
    keep = theta > UNRESOLVED_STIFFNESS * max(theta[0], 0.0)
    return (flexible @ Z[:, keep]) / theta[keep]
