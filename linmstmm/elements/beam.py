"""Euler-Bernoulli beam in space: exact (continuous) transfer matrix.

Local axes: x from the input end to the output end, y and z principal.
Along x the local state obeys ``Z' = A Z`` with (sign convention of the
package: the force is what the part at smaller x exerts on the part beyond)

    bending x-y:  v' = θz,  θz' = −mz/EIz,  mz' = −qy,  qy' = ρAω² v
    bending x-z:  w' = −θy, θy' = −my/EIy,  my' = qz,   qz' = ρAω² w
    axial:        u' = −qx/EA,             qx' = ρAω² u
    torsion:      θx' = −mx/GJ,            mx' = ρIpω² θx

and the transfer matrix is ``exp(A L)``, written in closed form. Every entry
is an entire function of ``w = ρAω²L⁴/EI`` (bending) or ``s = ρω²L²/E``
(axial, torsion), evaluated by power series for small arguments (no
cancellation: all terms positive) and by cosh/cos, sinh/sin otherwise.
"""
from __future__ import annotations

import math

import numpy as np

from linmstmm.elements.frames import state_rotation

#: |βL| below which the Krylov functions are summed as power series.
_SERIES_LIMIT = 2.0
_SERIES_TERMS = 14
#: 1/(4j + r)! for the series of the scaled Krylov functions.
_SERIES_COEFFS = np.array([[1.0 / math.factorial(4 * j + r) for j in range(_SERIES_TERMS)]
                           for r in range(4)])

# Local state indices of each deformation: (displacement, rotation, moment, force).
_BENDING_XY = [1, 5, 8, 10]
_BENDING_XZ = [2, 4, 7, 11]
_AXIAL = [0, 9]
_TORSION = [3, 6]
#: (w, θy, my, qz) = D (v, θ, m, q) maps the x-z plane onto the x-y form.
_XZ_SIGNS = np.array([1.0, -1.0, -1.0, 1.0])


def krylov(w) -> np.ndarray:
    """Scaled Krylov functions F_r(w) = Σ_j w^j/(4j+r)!, r = 0..3, shape (4, n).

    With z = w^(1/4): F0 = (cosh z + cos z)/2, F1 = (sinh z + sin z)/(2z),
    F2 = (cosh z − cos z)/(2z²), F3 = (sinh z − sin z)/(2z³).
    """
    w = np.asarray(w, dtype=float)
    out = np.empty((4,) + w.shape)
    small = w < _SERIES_LIMIT ** 4
    if np.any(small):
        powers = w[small][None, :] ** np.arange(_SERIES_TERMS)[:, None]
        out[:, small] = _SERIES_COEFFS @ powers
    if np.any(~small):
        z = w[~small] ** 0.25
        ch, c, sh, s = np.cosh(z), np.cos(z), np.sinh(z), np.sin(z)
        out[0, ~small] = (ch + c) / 2
        out[1, ~small] = (sh + s) / (2 * z)
        out[2, ~small] = (ch - c) / (2 * z**2)
        out[3, ~small] = (sh - s) / (2 * z**3)
    return out


def bending_transfer(EI, rhoA, L, omega) -> np.ndarray:
    """(n, 4, 4) transfer of (v, θ, m, q) in the x-y form of the bending equations."""
    omega = np.asarray(omega, dtype=float)
    w = rhoA * omega**2 * L**4 / EI
    F0, F1, F2, F3 = krylov(w)
    out = np.empty(omega.shape + (4, 4))
    out[:, 0] = np.stack([F0, L * F1, -L**2 * F2 / EI, L**3 * F3 / EI], axis=-1)
    out[:, 1] = np.stack([w * F3 / L, F0, -L * F1 / EI, L**2 * F2 / EI], axis=-1)
    out[:, 2] = np.stack([-EI * w * F2 / L**2, -EI * w * F3 / L, F0, -L * F1], axis=-1)
    out[:, 3] = np.stack([EI * w * F1 / L**3, EI * w * F2 / L**2, -w * F3 / L, F0], axis=-1)
    return out


def rod_transfer(stiffness, inertia, L, omega, rigid=False) -> np.ndarray:
    """(n, 2, 2) transfer of (displacement, force) of an axial rod or a shaft.

    stiffness : EA (N) or GJ (N m²). inertia : ρA (kg/m) or ρIp (kg m).
    rigid : no deformation, inertia kept (the limit stiffness -> inf).
    """
    omega = np.asarray(omega, dtype=float)
    out = np.empty(omega.shape + (2, 2))
    if rigid:
        out[:, 0, 0], out[:, 0, 1] = 1.0, 0.0
        out[:, 1, 0], out[:, 1, 1] = inertia * omega**2 * L, 1.0
        return out
    root_s = omega * L * np.sqrt(inertia / stiffness)  # k L
    sinc = np.sinc(root_s / np.pi)  # sin(kL)/(kL)
    out[:, 0, 0] = np.cos(root_s)
    out[:, 0, 1] = -L / stiffness * sinc
    out[:, 1, 0] = stiffness / L * root_s**2 * sinc
    out[:, 1, 1] = np.cos(root_s)
    return out


def beam_local_transfer(beam, omega, length=None) -> np.ndarray:
    """(n, 12, 12) transfer matrix of ``beam`` in its local axes.

    length : m, a piece of the beam (default: the whole beam).
    """
    L = beam.length if length is None else length
    rhoA = beam.rho * beam.A
    n = np.size(omega)
    out = np.zeros((n, 12, 12))
    out[np.ix_(range(n), _BENDING_XY, _BENDING_XY)] = bending_transfer(beam.E * beam.Iz, rhoA, L, omega)
    xz = bending_transfer(beam.E * beam.Iy, rhoA, L, omega)
    out[np.ix_(range(n), _BENDING_XZ, _BENDING_XZ)] = _XZ_SIGNS[:, None] * xz * _XZ_SIGNS[None, :]
    out[np.ix_(range(n), _AXIAL, _AXIAL)] = rod_transfer(
        beam.E * beam.A, rhoA, L, omega, rigid=not beam.axial)
    out[np.ix_(range(n), _TORSION, _TORSION)] = rod_transfer(
        beam.G * beam.J, beam.rho * beam.Ip, L, omega, rigid=not beam.torsion)
    return out


def traversal_axes(beam, reverse=False) -> np.ndarray:
    """(3, 3) local axes for transfer from ends[0] to ends[1] (or back if ``reverse``).

    Reversing turns local x and z around and keeps y: the section (Iy, Iz)
    and the equations are unchanged.
    """
    axes = np.asarray(beam.axes, dtype=float)
    return axes * np.array([[-1.0], [1.0], [-1.0]]) if reverse else axes


def beam_transfer(beam, omega, reverse=False, length=None) -> np.ndarray:
    """(n, 12, 12) inertial-frame transfer matrix of ``beam`` (or a piece of it).

    reverse : transfer from ends[1] to ends[0].
    length : m, the piece starting at the input end (default: whole beam).
    """
    rotation = state_rotation(traversal_axes(beam, reverse))
    return rotation @ beam_local_transfer(beam, omega, length) @ rotation.T
