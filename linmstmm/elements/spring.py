"""Elastic hinge: massless, zero length, six stiffnesses in its own axes.

Forces pass through unchanged; the displacement jumps by the compliance times
the internal force (the spring pulls its downstream end back):
``u_O = u_I - C_t q``, ``θ_O = θ_I - C_r m``. ``inf`` stiffness = zero
compliance = rigid direction. The matrix does not depend on which end is
the input (the spring is symmetric).
"""
from __future__ import annotations

import numpy as np

from linmstmm.elements.frames import M, Q, R, U
from linmstmm.numeric import number_type


def spring_compliance(k, axes) -> tuple[np.ndarray, np.ndarray]:
    """Translational and rotational compliance in the inertial frame.

    k : (6,) N/m and N m/rad, ``inf`` allowed; floats, or mpmath numbers
    (:func:`~linmstmm.numeric.numbers`: the compliances are then formed at the
    working precision). axes : (3, 3) rows = local axes.
    Returns (C_t, C_r), each (3, 3), m/N and rad/(N m).
    """
    k = np.asarray(k, dtype=number_type(k))
    axes = np.asarray(axes, dtype=float)
    compliance = 1.0 / k  # inf -> 0: rigid direction
    C_t = axes.T @ np.diag(compliance[:3]) @ axes
    C_r = axes.T @ np.diag(compliance[3:]) @ axes
    return C_t, C_r


def spring_transfer(k, axes, omega) -> np.ndarray:
    """Transfer matrix stack (n, 12, 12) of a spring; constant in omega."""
    C_t, C_r = spring_compliance(k, axes)
    U_single = np.eye(12, dtype=C_t.dtype)
    U_single[U, Q] = -C_t
    U_single[R, M] = -C_r
    return np.broadcast_to(U_single, (np.size(omega), 12, 12)).copy()


def damped_spring_transfer(k, c, axes, rate) -> np.ndarray:
    """Transfer matrix stack (n, 12, 12), complex, of a spring with dashpots.

    Each direction has the complex stiffness ``k + rate c``: at circular
    frequency ω of a harmonic motion ``rate = iω``, and ``rate = s`` at a
    complex frequency s of ``e^{st}``.

    Parameters
    ----------
    k : (6,) stiffnesses, N/m and N m/rad, ``inf`` allowed (rigid direction).
    c : (6,) viscous damping, N s/m and N m s/rad, same layout.
    axes : (3, 3) rows = the spring's local axes.
    rate : (n,) complex, 1/s.

    Returns
    -------
    (n, 12, 12) complex: ``u_O = u_I − C_t q``, ``θ_O = θ_I − C_r m`` with the
    compliances ``1 / (k + rate c)`` (0 in a rigid direction).
    """
    axes = np.asarray(axes, dtype=float)
    rate = np.reshape(np.asarray(rate, dtype=complex), (-1, 1))
    compliance = 1.0 / (np.asarray(k, dtype=float) + rate * np.asarray(c, dtype=float))  # (n, 6)
    stack = np.broadcast_to(np.eye(12, dtype=complex), (rate.shape[0], 12, 12)).copy()
    stack[:, U, Q] = -np.einsum("ji,nj,jk->nik", axes, compliance[:, :3], axes)
    stack[:, R, M] = -np.einsum("ji,nj,jk->nik", axes, compliance[:, 3:], axes)
    return stack
