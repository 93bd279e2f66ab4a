"""The constants a compiled program takes from the model's numbers, built for all
elements of a kind at once.

A program (:mod:`linmstmm.program`) holds each element's constant matrices
(U0 and U2 of ``U_j = U0 + ω² U2``, U_{j,Ik} and H_{j,Ik} of a body's other
inputs, a joint's released forces and jumps) at numbered places of its
``matrices``. The walk that lays the program out says which constant goes
where (:class:`Constants`); :meth:`Constants.fill` then builds them for all
elements of a kind at once, by compiled kernels (:mod:`linmstmm._constants_kernels`)
and numpy's products of their 3 × 3 factors: each of its matrices is, bit for bit,
that element's matrix alone as the element modules build it, the one
:class:`~linmstmm.deduction.Deduction` carries (a test holds them so), and a
parameter study's next model of the same structure refills the same places with
its numbers. On the launcher its 54 constants cost 0.7 ms built one element at a
time, 0.1 ms by numpy on stacks of elements, 0.04 ms so.
"""
from __future__ import annotations

import numpy as np

from linmstmm.elements.spring import joint_force, rotated


class Constants:
    """Which constant of the model's numbers goes where in a program's ``matrices``.

    The walk enters each constant as it records the operation that reads it (an
    element's U0 and U2 by :meth:`carry`), with the indices of ``matrices`` it took:
    ``rigid`` (element, U0, U2), ``spring`` (element, U0), ``junction`` U0 (the
    identity), ``other_input`` (element, k, U_{j,Ik}, H_{j,Ik}) of its input
    k + 2, ``joint`` (element, F of its released directions, its jumps' E).
    """

    def __init__(self):
        self.rigid: list[tuple[int, int, int]] = []
        self.spring: list[tuple[int, int]] = []
        self.junction: list[int] = []
        self.other_input: list[tuple[int, int, int, int]] = []
        self.joint: list[tuple[int, int, int]] = []
        self._indices = None  # rigid, spring, other_input as int arrays, made on the first fill

    def carry(self, e: int, kind: str, kinematic: int, inertial: int) -> None:
        """Element e's U0 goes to ``matrices[kinematic]``, a rigid body's U2 to ``[inertial]``."""
        if kind == "rigid":
            self.rigid.append((e, kinematic, inertial))
        elif kind == "spring":
            self.spring.append((e, kinematic))
        else:  # a junction
            self.junction.append(kinematic)

    def fill(self, deduction, matrices: np.ndarray) -> None:
        """Write every constant of ``deduction``'s numbers into ``matrices`` (K, 12, 12), in place.

        Every constant is entered (:meth:`carry` and the lists) before the first fill.

        Parameters
        ----------
        deduction : Deduction
            The deduced system the walk was made for, or one of the same structure
            (:func:`linmstmm.program._structure`).
        matrices : (K, 12, 12) float64
            The program's constants: zeros, or a program's constants of the same
            structure (whose padding is zeros already); each one written is padded with
            zeros to 12 × 12.
        """
        from linmstmm._constants_kernels import factors, place  # numba loads here

        elements = deduction.topology.elements
        if self._indices is None:
            self._indices = (np.array(self.rigid, dtype=np.int64).reshape(-1, 3),
                             np.array(self.spring, dtype=np.int64).reshape(-1, 2),
                             np.array(self.other_input, dtype=np.int64).reshape(-1, 4))
        rigid, spring, other_input = self._indices
        mass, com, inertia, inp, out = _rigid_numbers(elements, rigid)
        k, axes, release = _spring_numbers(elements, spring)
        arm, weighted, diagonal = factors(mass, com, inp, out, k, release, int(release.size > 0))
        place(matrices, rigid, inp, out, weighted, arm @ weighted, inertia, spring, rotated(axes, diagonal),
              other_input, _other_input_positions(elements, other_input))
        if self.junction:
            matrices[self.junction] = np.eye(12)
        for e, force, jump in self.joint:
            record = elements[e].record
            matrices[force] = padded(joint_force(record.axes, record.released))
            matrices[jump] = padded(deduction.jump_selection(e)[1])


def _rigid_numbers(elements, index: np.ndarray) -> tuple[np.ndarray, ...]:
    """(mass (n,) kg, com (n, 3) m, inertia (n, 3, 3) kg m², first input (n, 3) m,
    output (n, 3) m) of the rigid bodies ``index[:, 0]``."""
    bodies = [elements[e] for e in index[:, 0].tolist()]
    records = [body.record for body in bodies]
    return (np.array([r.mass for r in records], dtype=float), _stacked([r.com for r in records], (3,)),
            _stacked([r.inertia for r in records], (3, 3)),
            _stacked([body.ports[body.inputs[0]].position for body in bodies], (3,)),
            _stacked([body.ports[body.output].position for body in bodies], (3,)))


def _spring_numbers(elements, index: np.ndarray) -> tuple[np.ndarray, ...]:
    """(k (n, 6), axes (n, 3, 3), release (n, 6) 1 where released, or (0, 6) where no
    spring releases anything) of the springs ``index[:, 0]``."""
    records = [elements[e].record for e in index[:, 0].tolist()]
    releases = [record.release for record in records]
    released = np.array([_NOTHING_RELEASED if release is None else release for release in releases], dtype=float) \
        if any(release is not None for release in releases) else _NONE_RELEASED
    return _stacked([r.k for r in records], (6,)), _stacked([r.axes for r in records], (3, 3)), released


#: A spring's release where nothing is released, among others' (:func:`_spring_numbers`).
_NOTHING_RELEASED = np.zeros(6, dtype=bool)
#: The releases of springs none of which releases anything (:func:`_spring_numbers`).
_NONE_RELEASED = np.zeros((0, 6))


def _other_input_positions(elements, index: np.ndarray) -> np.ndarray:
    """(n, 3, 3) m: the first input, input k + 2 and output of element e, for each (e, k, …) of ``index``."""
    bodies = [elements[e] for e in index[:, 0].tolist()]
    return _stacked([position for body, k in zip(bodies, index[:, 1].tolist())
                     for position in (body.ports[body.inputs[0]].position, body.ports[body.inputs[k + 1]].position,
                                      body.ports[body.output].position)], (3, 3))


def _stacked(arrays: list, shape: tuple) -> np.ndarray:
    """(n,) + ``shape`` float64: the n ``arrays`` (each of ``shape``, or ``shape[0]`` vectors
    of ``shape[1:]`` in a row) stacked, also where there are none."""
    return np.array(arrays, dtype=float).reshape((-1,) + shape)


def padded(matrix) -> np.ndarray:
    """``matrix`` (at most 12 × 12) in the top left corner of a float (12, 12) of zeros."""
    out = np.zeros((12, 12))
    matrix = np.asarray(matrix, dtype=float)
    out[:matrix.shape[0], :matrix.shape[1]] = matrix
    return out
