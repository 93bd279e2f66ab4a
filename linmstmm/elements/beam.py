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

import functools
import math

import numpy as np

from linmstmm.elements.frames import state_rotation
from linmstmm.numeric import (constant_times, cos, cosh, frequencies, is_mp, magnitude, sin, sin_over, sinh,
                              sqrt, zeros_like_stack)

#: |βL| below which the Krylov functions are summed as power series.
_SERIES_LIMIT = 2.0
_SERIES_TERMS = 14
#: 1/(4j + r)! for the series of the scaled Krylov functions.
_SERIES_COEFFS = np.array([[1.0 / math.factorial(4 * j + r) for j in range(_SERIES_TERMS)]
                           for r in range(4)])

# Local state indices of each deformation: (displacement, rotation, moment, force).
_BENDING_XY = np.array([1, 5, 8, 10])
_BENDING_XZ = np.array([2, 4, 7, 11])
_AXIAL = np.array([0, 9])
_TORSION = np.array([3, 6])
#: (w, θy, my, qz) = D (v, θ, m, q) maps the x-z plane onto the x-y form.
_XZ_SIGNS = np.array([1.0, -1.0, -1.0, 1.0])


def _series_coefficients(mp: bool) -> np.ndarray:
    """(4, terms) table of 1/(4j + r)!, in mpmath at the working precision if ``mp``."""
    if not mp:
        return _SERIES_COEFFS
    import mpmath  # loaded already: the numbers of the mpmath path are its own

    terms = _SERIES_TERMS + int(mpmath.mp.dps)  # enough for |w| < 16 at any precision
    return np.array([[mpmath.mpf(1) / mpmath.factorial(4 * j + r) for j in range(terms)]
                     for r in range(4)], dtype=object)


def krylov(w) -> np.ndarray:
    """Scaled Krylov functions F_r(w) = Σ_j w^j/(4j+r)!, r = 0..3, shape (4, n).

    With z = w^(1/4) (any fourth root: the F_r are entire in w):
    F0 = (cosh z + cos z)/2, F1 = (sinh z + sin z)/(2z),
    F2 = (cosh z − cos z)/(2z²), F3 = (sinh z − sin z)/(2z³).
    w may be float, complex or mpmath (object) valued.
    """
    w = np.asarray(w)
    out = np.empty((4,) + w.shape, dtype=object if is_mp(w) else np.result_type(w, float))
    small = magnitude(w) < _SERIES_LIMIT ** 4
    if np.any(small):
        coefficients = _series_coefficients(is_mp(w))
        powers = w[small][None, :] ** np.arange(coefficients.shape[1])[:, None]
        out[:, small] = coefficients @ powers
    if np.any(~small):
        z = sqrt(sqrt(w[~small]))
        ch, c, sh, s = cosh(z), cos(z), sinh(z), sin(z)
        out[0, ~small] = (ch + c) / 2
        out[1, ~small] = (sh + s) / (2 * z)
        out[2, ~small] = (ch - c) / (2 * z**2)
        out[3, ~small] = (sh - s) / (2 * z**3)
    return out


def bending_wavenumber(beam, omega) -> float:
    """β = (ρA ω² / EI)^¼, 1/m, of the beam's softer bending plane at |omega| (rad/s).

    βL is how many e-foldings the beam functions grow over the beam.
    """
    return (beam.rho * beam.A * abs(omega) ** 2 / (beam.E * min(beam.Iy, beam.Iz))) ** 0.25


#: Entry (i, j) of the bending transfer of (v, θ, m, q) is
#: SIGN · L^L_POWER · EI^EI_POWER · w^W_POWER · F_r(w) with r = KRYLOV_INDEX.
_L_POWER = np.arange(4)[None, :] - np.arange(4)[:, None]
_KRYLOV_INDEX = _L_POWER % 4
_EI_POWER = (np.arange(4)[:, None] >= 2).astype(int) - (np.arange(4)[None, :] >= 2).astype(int)
_W_POWER = np.arange(4)[:, None] > np.arange(4)[None, :]
_SIGN = np.outer([1, 1, -1, 1], [1, 1, -1, 1])


def bending_transfers(EIs, rhoA, L, omega) -> list[np.ndarray]:
    """(n, 4, 4) transfer of (v, θ, m, q) in the x-y form of the bending equations,
    one per bending stiffness in ``EIs`` (one Krylov evaluation for all); ``L`` m, one
    length for all, or float64 (n,), one per frequency."""
    w = np.concatenate([rhoA * omega**2 * L**4 / EI for EI in EIs])
    functions = np.moveaxis(krylov(w)[_KRYLOV_INDEX], -1, 0)  # (len(EIs)·n, 4, 4)
    powers = np.where(_W_POWER, w[:, None, None], 1)
    out = []
    for k, EI in enumerate(EIs):
        if np.ndim(L):  # a length per frequency: (n, 4, 4)
            constants = _SIGN * L[:, None, None] ** _L_POWER * EI ** _EI_POWER
        else:
            constants = np.array([[int(_SIGN[i, j]) * L ** int(_L_POWER[i, j]) * EI ** int(_EI_POWER[i, j])
                                   for j in range(4)] for i in range(4)])
        part = slice(k * omega.size, (k + 1) * omega.size)
        out.append(constants * powers[part] * functions[part])
    return out


def rod_transfer(stiffness, inertia, L, omega, rigid=False) -> np.ndarray:
    """(n, 2, 2) transfer of (displacement, force) of an axial rod or a shaft.

    stiffness : EA (N) or GJ (N m²). inertia : ρA (kg/m) or ρIp (kg m).
    rigid : no deformation, inertia kept (the limit stiffness -> inf).
    """
    out = zeros_like_stack(omega, (2, 2))
    if rigid:
        out[:, 0, 0] = out[:, 1, 1] = 1
        out[:, 1, 0] = inertia * omega**2 * L
        return out
    if is_mp(omega):
        import mpmath  # loaded already: the numbers of the mpmath path are its own

        kL = omega * L * mpmath.sqrt(inertia / stiffness)
    else:
        kL = omega * L * math.sqrt(inertia / stiffness)
    sinc = sin_over(kL)
    out[:, 0, 0] = out[:, 1, 1] = cos(kL)
    out[:, 0, 1] = -L / stiffness * sinc
    out[:, 1, 0] = stiffness / L * kL**2 * sinc
    return out


def beam_local_transfer(beam, omega, length=None) -> np.ndarray:
    """(n, 12, 12) transfer matrix of ``beam`` in its local axes.

    length : m, a piece of the beam (default: the whole beam); or, in float64, an
    array (n,) of positive lengths, one piece per frequency.
    """
    omega = frequencies(omega)
    # In mpmath, products of the section properties are formed at the working
    # precision too (the inputs are exact binary floats).
    exact = float
    if is_mp(omega):
        import mpmath  # loaded already: the numbers of the mpmath path are its own

        exact = mpmath.mpf
    E, G, rho, A, Iy, Iz, J, Ip = (exact(getattr(beam, name))
                                   for name in ("E", "G", "rho", "A", "Iy", "Iz", "J", "Ip"))
    L = exact(beam.length if length is None else length) if np.ndim(length) == 0 else np.asarray(length, float)
    out = zeros_like_stack(omega, (12, 12))
    xy, xz = bending_transfers((E * Iz, E * Iy), rho * A, L, omega)
    out[:, _BENDING_XY[:, None], _BENDING_XY] = xy
    out[:, _BENDING_XZ[:, None], _BENDING_XZ] = _XZ_SIGNS[:, None] * xz * _XZ_SIGNS[None, :]
    out[:, _AXIAL[:, None], _AXIAL] = rod_transfer(E * A, rho * A, L, omega, rigid=not beam.axial)
    out[:, _TORSION[:, None], _TORSION] = rod_transfer(G * J, rho * Ip, L, omega, rigid=not beam.torsion)
    return out


def traversal_axes(axes, reverse=False) -> np.ndarray:
    """(3, 3) local axes for transfer from ends[0] to ends[1] (or back if ``reverse``),
    from a beam's ``axes``.

    Reversing turns local x and z around and keeps y: the section (Iy, Iz)
    and the equations are unchanged.
    """
    axes = np.asarray(axes, dtype=float)
    return axes * np.array([[-1.0], [1.0], [-1.0]]) if reverse else axes


def beam_transfer(beam, omega, reverse=False, length=None) -> np.ndarray:
    """(n, 12, 12) inertial-frame transfer matrix of ``beam`` (or a piece of it).

    reverse : transfer from ends[1] to ends[0].
    length : m, the piece starting at the input end (default: whole beam), or
    float64 (n,), one piece per frequency (:func:`beam_states`).
    """
    rotation = _state_rotation(tuple(np.ravel(beam.axes)), reverse)
    local = beam_local_transfer(beam, omega, length)
    if not is_mp(local):
        return rotation @ local @ rotation.T
    # mpmath: only the rotation's non-zero entries multiply (three quarters are zero)
    turned = constant_times(rotation, local)
    return np.swapaxes(constant_times(rotation, np.swapaxes(turned, 1, 2)), 1, 2)


#: Transfer matrices :func:`beam_states` forms in one evaluation, at most (unless one distance
#: needs more: one per frequency): 19 MB each of the evaluation's few (n, 12, 12) arrays.
STATES_BATCH = 1 << 14


def beam_states(beam, omega, start: np.ndarray, distances, reverse: bool = False) -> np.ndarray:
    """(n, s, 12) states along ``beam`` at ``distances`` (s,) m from its input end, carried
    from the states ``start`` (n, 12) there at each of ``omega`` (n,) rad/s by the exact
    transfer of each piece (:func:`beam_transfer`, ``reverse`` as there), every piece
    of every frequency in one evaluation; a distance of 0 is ``start`` itself."""
    omega = np.asarray(omega, dtype=float)
    distances = np.asarray(distances, dtype=float)
    out = np.empty((omega.size, distances.size, 12))
    out[:, distances <= 0] = start[:, None]
    inside = np.flatnonzero(distances > 0)
    batch = max(1, STATES_BATCH // max(omega.size, 1))  # distances an evaluation takes
    for first in range(0, inside.size, batch):
        some = inside[first:first + batch]
        transfers = beam_transfer(beam, np.tile(omega, some.size), reverse, np.repeat(distances[some], omega.size))
        out[:, some] = np.einsum("snij,nj->nsi", transfers.reshape(some.size, omega.size, 12, 12), start)
    return out


@functools.lru_cache(maxsize=256)
def _state_rotation(axes: tuple, reverse: bool) -> np.ndarray:
    """:func:`state_rotation` of :func:`traversal_axes`, built once per beam and direction
    (``axes``: the beam's axes, flattened)."""
    rotation = state_rotation(traversal_axes(np.reshape(axes, (3, 3)), reverse))
    rotation.flags.writeable = False  # shared by every caller
    return rotation
