"""The constants of a compiled program laid out in compiled code: the rigid bodies', the
springs' and the other inputs' matrices written into the program's ``matrices``, each
entry as the element modules write it for one element
(:func:`~linmstmm.elements.rigid.rigid_transfer_parts`,
:func:`~linmstmm.elements.spring.spring_constant_transfer`,
:func:`~linmstmm.elements.rigid.force_extraction`,
:func:`~linmstmm.elements.rigid.position_incidence`, the readable references a test holds
these to bit for bit, the sign of every zero included).

The products of two 3 × 3 matrices (a body's moment rows, a spring's compliances turned
into the inertial frame) are not formed here: numpy forms them (``arm @ weighted``,
:func:`~linmstmm.elements.spring.rotated`), by BLAS, whose sums differ from a plain
loop's in the last bit (on this machine one entry in three of random 3 × 3 products).
:mod:`linmstmm.program_constants` calls :func:`factors` for their factors, numpy for
the products, then :func:`place` for the rest: on the launcher 0.04 ms against 0.1 ms
for some eighty numpy calls on stacks of a few elements.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)


@njit(cache=True)
def factors(mass, com, inp, out, k, release, released):
    """The factors numpy multiplies: the rigid bodies' moment rows are ``arm @ weighted``,
    the springs' compliances in the inertial frame ``axesᵀ diagonal axes``
    (:func:`~linmstmm.elements.spring.rotated`).

    Parameters
    ----------
    mass : (nr,) float64
        kg.
    com, inp, out : (nr, 3) float64
        Mass centres, first inputs and outputs, m.
    k : (ns, 6) float64
        Stiffnesses, N/m and N m/rad, ``inf`` a rigid direction.
    release : (ns, 6) float64
        1 where a direction is released (its compliance 0), read where ``released``.
    released : int
        0: nothing is released in any spring (the compliance is 1 / k throughout).

    Returns
    -------
    arm : (nr, 3, 3) float64
        −skew(out − com).
    weighted : (nr, 3, 6) float64
        ``[I | −skew(com − inp)] m``: the mass centre's displacement from the input's
        displacement and rotation, times the mass.
    diagonal : (ns, 2, 3, 3) float64
        Translational and rotational compliances on the diagonals, zeros elsewhere.
    """
    n = mass.size
    arm, weighted = np.empty((n, 3, 3)), np.empty((n, 3, 6))
    lever = np.empty((3, 3))
    for b in range(n):
        _skew(out[b] - com[b], lever)
        arm[b] = -lever
        _skew(com[b] - inp[b], lever)
        for i in range(3):
            for j in range(3):
                weighted[b, i, j] = (1.0 if i == j else 0.0) * mass[b]
                weighted[b, i, 3 + j] = -lever[i, j] * mass[b]
    diagonal = np.zeros((k.shape[0], 2, 3, 3))
    for s in range(k.shape[0]):
        for d in range(6):
            free = released != 0 and release[s, d] != 0.0
            diagonal[s, d // 3, d % 3, d % 3] = 0 * k[s, d] if free else 1 / k[s, d]
    return arm, weighted, diagonal


@njit(cache=True)
def place(matrices, rigid, inp, out, weighted, moments, inertia, spring, compliances, other_input, positions):
    """Write the constants into ``matrices`` (K, 12, 12), in place.

    Parameters
    ----------
    matrices : (K, 12, 12) float64
        The program's constants.
    rigid : (nr, 3) int64
        (element, U0 index, U2 index) of each rigid body.
    inp, out : (nr, 3) float64
        Its first input and output, m.
    weighted, moments, inertia : (nr, 3, 6), (nr, 3, 6), (nr, 3, 3) float64
        :func:`factors`'s ``weighted``, ``arm @ weighted`` and the inertia about
        the mass centre, kg m².
    spring : (ns, 2) int64
        (element, U0 index) of each spring.
    compliances : (ns, 2, 3, 3) float64
        Its translational and rotational compliances in the inertial frame.
    other_input : (no, 4) int64
        (element, k, U_{j,Ik} index, H_{j,Ik} index) of input k + 2 of a body.
    positions : (no, 3, 3) float64
        Its first input, input k + 2 and output, m.
    """
    lever = np.empty((3, 3))
    for b in range(rigid.shape[0]):
        kinematic, inertial = matrices[rigid[b, 1]], matrices[rigid[b, 2]]
        _identity(kinematic)
        _skew(out[b] - inp[b], lever)
        kinematic[0:3, 3:6] = -lever
        _skew(inp[b] - out[b], lever)
        kinematic[6:9, 9:12] = lever
        inertial[:] = 0.0
        inertial[9:12, 0:6] = weighted[b]
        inertial[6:9, 0:6] = moments[b]
        inertial[6:9, 3:6] += inertia[b]
    for s in range(spring.shape[0]):
        single = matrices[spring[s, 1]]
        _identity(single)
        single[0:3, 9:12] = -compliances[s, 0]
        single[3:6, 6:9] = -compliances[s, 1]
    for o in range(other_input.shape[0]):
        extraction, incidence = matrices[other_input[o, 2]], matrices[other_input[o, 3]]
        extraction[:] = 0.0
        for i in range(3):
            extraction[6 + i, 6 + i] = extraction[9 + i, 9 + i] = 1.0
        _skew(positions[o, 1] - positions[o, 2], lever)
        extraction[6:9, 9:12] = lever
        incidence[0:6] = 0.0  # rows 6: are zeros already (Constants.fill)
        for i in range(6):
            incidence[i, i] = 1.0
        _skew(positions[o, 1] - positions[o, 0], lever)
        incidence[0:3, 3:6] = lever


@njit(cache=True)
def _skew(r, out):
    """``out`` (3, 3) = :func:`linmstmm.elements.frames.skew` of ``r`` (3,), in place."""
    out[:] = 0.0
    out[0, 1], out[0, 2] = -r[2], r[1]
    out[1, 0], out[1, 2] = r[2], -r[0]
    out[2, 0], out[2, 1] = -r[1], r[0]


@njit(cache=True)
def _identity(matrix):
    """``matrix`` (12, 12) = the identity, in place."""
    matrix[:] = 0.0
    for i in range(12):
        matrix[i, i] = 1.0
