"""Elastic hinge: massless, zero length, six stiffnesses in its own axes.

Forces pass through unchanged; the displacement jumps by the compliance times
the internal force (the spring pulls its downstream end back):
``u_O = u_I - C_t q``, ``θ_O = θ_I - C_r m``. ``inf`` stiffness = zero
compliance = rigid direction. The matrix does not depend on which end is
the input (the spring is symmetric).

A released direction (a joint: pin, universal, ball, slider) transmits no
force and its jump Δ is free: the transfer becomes
``Z_O = U Z_I + E Δ`` with U rigid in that direction, and the condition
``F Z_I = 0`` (the force along it vanishes) holds on the input side, as a
hinge element does in the transfer matrix method for multibody systems: one
more unknown and one more equation per released direction
(:func:`joint_jump`, :func:`joint_force`).
"""
from __future__ import annotations

import numpy as np

from linmstmm.elements.frames import FORCE_INDEX, M, Q, R, U, identities
from linmstmm.numeric import number_type

#: The released directions of a spring with none (:attr:`linmstmm.model.Spring.released`):
#: no indices, read-only, one array shared by every such spring.
NO_RELEASED_INDICES = np.zeros(0, dtype=np.intp)
NO_RELEASED_INDICES.setflags(write=False)


def spring_compliance(k, axes, release=None) -> tuple[np.ndarray, np.ndarray]:
    """Translational and rotational compliance in the inertial frame.

    k : (..., 6) N/m and N m/rad, ``inf`` allowed; floats, or mpmath numbers
    (:func:`~linmstmm.numeric.numbers`: the compliances are then formed at the
    working precision). axes : (..., 3, 3) rows = local axes. release : (..., 6)
    bool or None: released directions get zero compliance (their jump is an
    unknown of its own, :func:`joint_jump`). One spring, or a stack of springs
    along the leading axes (each the same numbers as alone).
    Returns (C_t, C_r), each (..., 3, 3), m/N and rad/(N m).
    """
    k = np.asarray(k, dtype=number_type(k))
    axes = np.asarray(axes, dtype=float)
    if release is None:
        compliance = 1 / k  # inf -> 0: rigid direction
    else:
        free = np.broadcast_to(np.asarray(release, bool), k.shape)
        compliance = 1 / np.where(free, 1, k)
        compliance[free] = 0 * k[free]
    diagonal = np.zeros(k.shape[:-1] + (2, 9), dtype=k.dtype)  # translational, rotational: diag of each
    diagonal[..., ::4] = compliance.reshape(k.shape[:-1] + (2, 3))
    both = rotated(axes, diagonal.reshape(k.shape[:-1] + (2, 3, 3)))
    return both[..., 0, :, :], both[..., 1, :, :]


def rotated(axes: np.ndarray, diagonal: np.ndarray) -> np.ndarray:
    """``axesᵀ D axes`` for each of a spring's two compliances D (in its own axes).

    Parameters
    ----------
    axes : (..., 3, 3) float
        Rows = the springs' local axes.
    diagonal : (..., 2, 3, 3)
        Translational (m/N) and rotational (rad/(N m)) compliances in the local axes.

    Returns
    -------
    (..., 2, 3, 3)
        The same in the inertial frame (the program's constants take them from here:
        :mod:`linmstmm._constants_kernels`).
    """
    axes = axes[..., None, :, :]
    return np.swapaxes(axes, -1, -2) @ diagonal @ axes


def spring_constant_transfer(k, axes, release=None) -> np.ndarray:
    """(..., 12, 12) transfer matrix of a spring (it does not depend on ω), or of a
    stack of springs; k, axes, release as :func:`spring_compliance`."""
    C_t, C_r = spring_compliance(k, axes, release)
    single = identities(C_t.shape[:-2], 12, dtype=C_t.dtype)
    single[..., U, Q] = -C_t
    single[..., R, M] = -C_r
    return single


def spring_transfer(k, axes, omega, release=None) -> np.ndarray:
    """Transfer matrix stack (n, 12, 12) of a spring; constant in omega.

    k, axes, release : as :func:`spring_compliance`, one spring. omega : (n,) rad/s.
    """
    return np.broadcast_to(spring_constant_transfer(k, axes, release), (np.size(omega), 12, 12)).copy()


def damped_spring_transfer(k, c, axes, rate, release=None) -> np.ndarray:
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
    release : (6,) bool or None: released directions get zero compliance (their
    jump is an unknown of its own, :func:`joint_jump`); a dashpot there is
    refused before (:func:`linmstmm.forced.refuse_released_dashpots`).

    Returns
    -------
    (n, 12, 12) complex: ``u_O = u_I − C_t q``, ``θ_O = θ_I − C_r m`` with the
    compliances ``1 / (k + rate c)`` (0 in a rigid direction).
    """
    axes = np.asarray(axes, dtype=float)
    rate = np.reshape(np.asarray(rate, dtype=complex), (-1, 1))
    with np.errstate(divide="ignore", invalid="ignore"):  # k = 0, c = 0: a released direction, zeroed below
        # (1 / 0 in complex is nan, an invalid value; a direction kept has k > 0)
        compliance = 1.0 / (np.asarray(k, dtype=float) + rate * np.asarray(c, dtype=float))  # (n, 6)
    if release is not None:
        compliance[:, np.asarray(release, bool)] = 0.0
    stack = identities((rate.shape[0],), 12, dtype=complex)
    stack[:, U, Q] = -np.einsum("ji,nj,jk->nik", axes, compliance[:, :3], axes)
    stack[:, R, M] = -np.einsum("ji,nj,jk->nik", axes, compliance[:, 3:], axes)
    return stack


def joint_jump(axes, released) -> np.ndarray:
    """(12, r) E: the state jump across the spring from its released jumps Δ (r,).

    axes : (3, 3) rows = local axes. released : (r,) direction indices 0..5
    (x, y, z, rx, ry, rz in the spring's axes). Δ_j is m for a translation,
    rad for a rotation, along local axis ``released[j] % 3``.
    """
    axes = np.asarray(axes, dtype=float)
    jump = np.zeros((12, len(released)))
    for j, direction in enumerate(released):
        block = U if direction < 3 else R
        jump[block, j] = axes[direction % 3]
    return jump


def joint_force(axes, released) -> np.ndarray:
    """(r, 12) F: the force (N) or moment (N m) of the state along each released direction.

    ``F Z = 0`` is the condition a released direction adds; F pairs with
    :func:`joint_jump` by work (``F[j]`` reads the force that does work on Δ_j).
    """
    jump = joint_jump(axes, released)
    force = np.zeros((len(released), 12))
    force[:, FORCE_INDEX] = jump[:6].T
    return force
