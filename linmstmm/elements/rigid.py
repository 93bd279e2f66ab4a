"""Rigid body: transfer matrix between two ports, and the pieces of the
multi-input body (eqs 3-4 of the multiple launch rocket system study, ``docs/method.md``).

Newton-Euler about the mass centre c, harmonic at ω (inertia force
m ω² u_c, inertia moment ω² J_c θ), with the sign convention of the package
(the force at the input is applied to the body, the force at the output is
what the body applies downstream):

    u_O = u_I + θ × (O − I),           θ_O = θ_I,
    q_O = q_I + ω² m u_c,              u_c = u_I + θ × (c − I),
    m_O = m_I + (I − c) × q_I − (O − c) × q_O + ω² J_c θ.

A body with inputs I_1..I_L and output O:
``Z_O = U_j Z_I1 + Σ_k U_{j,Ik} Z_Ik`` and ``H_j Z_I1 = H_{j,Ik} Z_Ik``.
"""
from __future__ import annotations

import numpy as np

from linmstmm.elements.frames import M, Q, R, U, identities, skew
from linmstmm.numeric import frequencies, number_type


def rigid_transfer_parts(mass, com, inertia, inp, out) -> tuple[np.ndarray, np.ndarray]:
    """(kinematic, inertial), each (..., 12, 12): ``U(ω) = kinematic + ω² inertial``;
    only the block inertial[..., 6:, :6] (forces and moments from displacements and
    rotations) is non-zero.

    mass : (...) kg. com, inp, out : (..., 3) positions, m. inertia : (..., 3, 3)
    about the mass centre, kg m². One body, or a stack of bodies along the leading
    axes (each the same numbers as alone). Floats, or mpmath numbers
    (:func:`~linmstmm.numeric.numbers`): then both matrices are object arrays.
    """
    mass, inp, out, com, inertia = (np.asarray(p) for p in (mass, inp, out, com, inertia))
    dtype = number_type(mass, com, inertia, inp, out)
    arms = skew(np.stack([out - inp, inp - out, com - inp, out - com]))  # the four at once: one call, not four
    kinematic = identities(mass.shape, 12, dtype=dtype)
    kinematic[..., U, R] = -arms[0]
    kinematic[..., M, Q] = arms[1]
    weighted = np.zeros(mass.shape + (3, 6)).astype(dtype, copy=False)  # u_c = this @ (u_I, θ_I), times m
    weighted[..., :3] = np.eye(3)
    weighted[..., 3:] = -arms[2]
    weighted *= mass[..., None, None]
    inertial = np.zeros(mass.shape + (12, 12), dtype=dtype)
    inertial[..., Q, 0:6] = weighted
    inertial[..., M, 0:6] = -arms[3] @ weighted
    inertial[..., M, R] += inertia
    return kinematic, inertial


def rigid_transfer(mass, com, inertia, inp, out, omega) -> np.ndarray:
    """Transfer matrix stack (n, 12, 12) from port ``inp`` to port ``out``.

    mass : kg. com, inp, out : (3,) positions, m. inertia : (3, 3) about the
    mass centre, kg m². omega : (n,) rad/s.
    """
    kinematic, inertial = rigid_transfer_parts(mass, com, inertia, inp, out)
    return kinematic + frequencies(omega).reshape(-1, 1, 1) ** 2 * inertial


def force_extraction(inp_k, out) -> np.ndarray:
    """(..., 12, 12) U_{j,Ik}: carries the force and moment of input k to the output
    (positions (..., 3), float or mpmath numbers, as in :func:`rigid_transfer_parts`)."""
    arm = np.asarray(inp_k) - np.asarray(out)
    extraction = np.zeros(arm.shape[:-1] + (12, 12), dtype=number_type(inp_k, out))
    extraction[..., M, M] = np.eye(3)
    extraction[..., Q, Q] = np.eye(3)
    extraction[..., M, Q] = skew(arm)
    return extraction


def position_incidence(inp_1, inp_k) -> np.ndarray:
    """(..., 6, 12) H_{j,Ik} with ``H_j Z_I1 = H_{j,Ik} Z_Ik`` (rigid kinematics; H_j takes
    rows 0:6, the displacement and rotation, as the deduction does directly);
    positions (..., 3) as in :func:`force_extraction`."""
    arm = np.asarray(inp_k) - np.asarray(inp_1)
    incidence = identities(arm.shape[:-1], 6, 12, dtype=number_type(inp_1, inp_k))
    incidence[..., U, R] = skew(arm)
    return incidence
