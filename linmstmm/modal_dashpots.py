"""Spring dashpots in the modal time response: their damping in modal
coordinates, and the exact response of the modal equations they couple.

A dashpot ``c`` on a spring resists the rate of the spring's elongation in
each of its directions. In the undamped modes φ_k (modal masses M_k) it adds
the damping matrix

    C_jk = Σ_springs Σ_d c_d (e_d · Δφ_j)(e_d · Δφ_k),

Δφ the motion of the spring's second end less its first (translation and
rotation), e_d its local directions; the modal equations become

    q̈ + (diag(c_k) + M⁻¹C) q̇ + diag(ω_k²) q = p g(t),

coupled wherever C is not diagonal. With z = (q, q̇) they are ż = A z + b g,
solved exactly through the eigenvalues λ of A: each eigen-coordinate obeys
η̇ = λ η + β g, and 1/(s − λ) = (s − λ̄)/(s² − 2 Re λ s + |λ|²), so η is
β (ẏ − λ̄ y) with y the response of the oscillator ÿ − 2 Re λ ẏ + |λ|² y = g
(:func:`linmstmm.duhamel.unit_response`, exact for every time function and
damping; a real λ gives a critically damped oscillator, λ = 0 a double
integral). The modes no dashpot moves keep their own equations.

The dashpots act only through the modes in the sum: what the modes above
would carry of them is left out, as their stiffness and mass are (the static
correction restores the stiffness part).
"""
from __future__ import annotations

import numpy as np

from linmstmm.duhamel import unit_response
from linmstmm.loads import TimeFunction
from linmstmm.model import Model

#: A mode whose dashpot damping (row and column of C) is below this fraction of
#: C's largest entry is not moved by any dashpot: it keeps its own equation.
UNTOUCHED = 1e-12
#: Eigenvectors of A whose condition number exceeds this are (nearly) defective:
#: two damped modes at one critically damped λ, where the eigen-solution loses
#: every digit.
DEFECTIVE = 1e8


class DefectiveDampingError(ValueError):
    """Dashpots that make two damped modes (nearly) coincide: the coupled modal
    equations cannot be solved through their eigenvalues."""


def modal_dashpots(model: Model, point_displacements: dict, modal_mass: np.ndarray) -> np.ndarray | None:
    """(n, n) M⁻¹C of the springs' dashpots in the modal coordinates, 1/s, or None
    where the model has no dashpot.

    Parameters
    ----------
    model : Model
        The model (its springs' ``c``, ``ends`` and ``axes``).
    point_displacements : dict
        Point name -> (n, 6) the modes' displacement (m) and rotation (rad) at
        it, inertial axes (:attr:`linmstmm.modes.ModalResult.point_displacements`).
    modal_mass : numpy.ndarray, shape (n,)
        M_k of the modes, kg.

    Returns
    -------
    numpy.ndarray, shape (n, n), or None
        Row j: the damping force on mode j per unit modal velocity q̇_k,
        divided by M_j.
    """
    damped = [spring for spring in model.springs if spring.c is not None and np.any(spring.c > 0)]
    if not damped:
        return None
    modal_mass = np.asarray(modal_mass, dtype=float)
    C = np.zeros((modal_mass.size, modal_mass.size))
    for spring in damped:
        first, second = (point_displacements[end] for end in spring.ends)
        jump = second - first  # (n, 6)
        local = np.concatenate([jump[:, :3] @ spring.axes.T, jump[:, 3:] @ spring.axes.T], axis=1)
        C += (local * spring.c) @ local.T
    return C / modal_mass[:, None]


def coupled_unit_response(omega, rates, coupling, participation, function: TimeFunction, times):
    """Exact response of q̈ + (diag(rates) + coupling) q̇ + diag(ω²) q = p g(t) from rest.

    Parameters
    ----------
    omega, rates : array_like, shape (n,)
        ω_k, rad/s, and the modes' own damping rates c_k, 1/s.
    coupling : array_like, shape (n, n)
        M⁻¹C of the dashpots, 1/s (:func:`modal_dashpots`).
    participation : array_like, shape (n,)
        p_k per unit of g.
    function : TimeFunction
        The load's time function g.
    times : array_like, shape (n_t,)
        s, increasing and equally spaced.

    Returns
    -------
    tuple of numpy.ndarray
        (q, q̇, q̈), each (n_t, n), per unit of g.

    Raises
    ------
    DefectiveDampingError
        Where two modes the dashpots couple meet at one critically damped λ.
    """
    omega, rates = np.asarray(omega, dtype=float), np.asarray(rates, dtype=float)
    coupling, participation = np.asarray(coupling, dtype=float), np.asarray(participation, dtype=float)
    touched = _touched(coupling)
    histories = np.zeros((3, np.size(times), omega.size))
    alone = ~touched  # modes no dashpot moves: their own equations
    histories[:, :, alone] = np.stack(unit_response(omega[alone], rates[alone], function, times)) * participation[alone]
    if not touched.any():
        return tuple(histories)
    w, c, p = omega[touched], rates[touched], participation[touched]
    m = w.size
    A = np.block([[np.zeros((m, m)), np.eye(m)],
                  [-np.diag(w**2), -(np.diag(c) + coupling[np.ix_(touched, touched)])]])
    lam, V = np.linalg.eig(A)
    if np.linalg.cond(V) > DEFECTIVE:
        raise DefectiveDampingError("the dashpots make two damped modes coincide (critically damped at one "
                                    "rate): the coupled modal equations cannot be solved by their eigenvalues")
    beta = np.linalg.solve(V, np.r_[np.zeros(m), p])
    y, y_rate, y_acceleration = unit_response(np.abs(lam), -2 * lam.real, function, times)  # (n_t, 2m)
    state = ((y_rate - np.conj(lam) * y) * beta) @ V.T  # (n_t, 2m): (q, q̇) of the touched modes
    q, velocity = state[:, :m].real, state[:, m:].real
    # g(t) as the oscillators carry it (a kick is not in it): ÿ − 2 Re λ ẏ + |λ|² y of any of them
    load = y_acceleration[:, 0] - 2 * lam[0].real * y_rate[:, 0] + np.abs(lam[0]) ** 2 * y[:, 0]
    acceleration = np.outer(load, p) - w**2 * q - velocity @ (np.diag(c) + coupling[np.ix_(touched, touched)]).T
    for history, coupled in zip(histories, (q, velocity, acceleration)):
        history[:, touched] = coupled
    return tuple(histories)


def _touched(coupling: np.ndarray) -> np.ndarray:
    """(n,) bool: the modes some dashpot moves (row or column of ``coupling`` above
    UNTOUCHED of its largest entry)."""
    size = np.abs(coupling).max(initial=0.0)
    if size == 0:
        return np.zeros(coupling.shape[0], dtype=bool)
    return (np.abs(coupling).max(axis=1) > UNTOUCHED * size) | (np.abs(coupling).max(axis=0) > UNTOUCHED * size)
