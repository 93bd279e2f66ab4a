"""Damped problems on the assembled model: the springs' dashpot matrix, the
direct complex receptance solve and the complex roots of the quadratic
eigenproblem."""
from __future__ import annotations

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from linmstmm.fe.assembly import FEModel, assemble
from linmstmm.fe.layout import _spring_directions, _Triplets
from linmstmm.fe.sparse import symmetric_part
from linmstmm.model import Model

_TWO_PI = 2.0 * np.pi


def dashpot_matrix(model: Model, fe: FEModel) -> sp.csr_matrix:
    """(n_dof, n_dof) sparse viscous damping of the springs' dashpots ``c``.

    Assembled as the springs' stiffness is: ``C = Hᵀ diag(c) H`` with H the
    elongation of each spring direction that has a dashpot (N s/m, N m s/rad),
    in the reduced DOFs of ``fe`` (assembled from the same ``model``).
    """
    rows, damping = _Triplets(), []
    for spring in model.springs:
        for component, cols, values in _spring_directions(spring, fe.dof_index, kept_only=False):
            if spring.c is not None and spring.c[component] > 0:
                rows.add(rows.new_rows(1), cols, values)
                damping.append(float(spring.c[component]))
    H = rows.matrix(fe.n_full) @ fe.T
    return symmetric_part(H.T @ sp.diags(np.asarray(damping)) @ H)


def harmonic_receptance(model: Model, point: str, vector, frequencies_hz, points,
                        elements_per_beam: int = 8, damping=None) -> np.ndarray:
    """Receptance by the direct complex solve (K + iΩ(C + αM + βK) − Ω²M) x = f.

    Parameters
    ----------
    model : the model; C holds its springs' dashpots (:func:`dashpot_matrix`).
    point : the loaded point. vector : (6,) [force N, moment N m], inertial axes.
    frequencies_hz : (n_f,) Hz. points : response point names.
    elements_per_beam : the mesh. damping : Rayleigh (α 1/s, β s) or None.

    Returns
    -------
    (n_f, n_points, 6) complex displacements (m) and rotations (rad) per unit
    of ``vector``, inertial axes: exact for springs and rigid bodies, with the
    mesh's discretisation error for beams.
    """
    fe = assemble(model, elements_per_beam)
    alpha, beta = (0.0, 0.0) if damping is None else damping
    viscous = dashpot_matrix(model, fe) + alpha * fe.M + beta * fe.K
    load = np.zeros(fe.n_full)
    load[fe.dof_index.point(point)] = vector
    load = fe.T.T @ load
    picks = np.concatenate([fe.dof_index.point(p) for p in points])
    out = np.empty((len(frequencies_hz), len(points) * 6), dtype=complex)
    for i, omega in enumerate(_TWO_PI * np.asarray(frequencies_hz, float)):
        dynamic = (fe.K + 1j * omega * viscous - omega**2 * fe.M).tocsc()
        out[i] = (fe.T @ splu(dynamic).solve(load.astype(complex)))[picks]
    return out.reshape(len(frequencies_hz), len(points), 6)


def damped_roots(model: Model, elements_per_beam: int = 8) -> np.ndarray:
    """Complex roots s (1/s) of the quadratic eigenproblem (K + sC + s²M) x = 0.

    C holds the springs' dashpots (:func:`dashpot_matrix`) and the model's
    Rayleigh ``[damping]`` αM + βK. Linearised to the generalized eigenproblem
    s [[I, 0], [0, M]] y = [[0, I], [−K, −C]] y, y = (x, s x), solved densely.

    Returns
    -------
    (m,) the finite roots with Im s > 0 (one of each conjugate pair:
    s = −ζω_n + iω_d), ascending in Im s. Massless DOFs give infinite roots,
    which are dropped; overdamped and zero (rigid-body) roots are real and
    left out.
    """
    fe = assemble(model, elements_per_beam)
    alpha, beta = (0.0, 0.0) if model.damping is None else model.damping
    damping = (dashpot_matrix(model, fe) + alpha * fe.M + beta * fe.K).toarray()
    n = fe.n_dof
    identity, zero = np.eye(n), np.zeros((n, n))
    roots = la.eigvals(np.block([[zero, identity], [-fe.K.toarray(), -damping]]),
                      np.block([[identity, zero], [zero, fe.M.toarray()]]))
    roots = roots[np.isfinite(roots) & (roots.imag > 0)]
    return roots[np.argsort(roots.imag)]
