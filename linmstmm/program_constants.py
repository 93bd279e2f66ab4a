"""The constants a compiled program takes from the model's numbers, built for all
elements of a kind at once.

A program (:mod:`linmstmm.program`) holds each element's constant matrices
(U0 and U2 of ``U_j = U0 + ω² U2``, U_{j,Ik} and H_{j,Ik} of a body's other
inputs, a joint's released forces and jumps) at numbered places of its
``matrices``. The walk that lays the program out says which constant goes
where (:class:`Constants`); :meth:`Constants.fill` then builds them with the
element modules' own functions, called once per kind on a stack of elements
(:func:`~linmstmm.elements.rigid.rigid_transfer_parts` and the others take a
stack; each of its matrices is, bit for bit, that element's matrix alone, the
one :class:`~linmstmm.deduction.Deduction` carries), and a parameter study's
next model of the same structure refills the same places with its numbers.
On the launcher its 54 constants cost 0.7 ms built one element at a time, 0.15 ms so.
"""
from __future__ import annotations

import numpy as np

from linmstmm.elements.rigid import force_extraction, position_incidence, rigid_transfer_parts
from linmstmm.elements.spring import joint_force, spring_constant_transfer


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
        elements = deduction.topology.elements
        if self._indices is None:
            self._indices = tuple(np.array(entries, dtype=np.int64)
                                  for entries in (self.rigid, self.spring, self.other_input))
        rigid, spring, other_input = self._indices
        if self.rigid:
            _fill_rigid(elements, rigid, matrices)
        if self.spring:
            _fill_springs(elements, spring, matrices)
        if self.junction:
            matrices[self.junction] = np.eye(12)
        if self.other_input:
            _fill_other_inputs(elements, other_input, matrices)
        for e, force, jump in self.joint:
            record = elements[e].record
            matrices[force] = padded(joint_force(record.axes, record.released))
            matrices[jump] = padded(deduction.jump_selection(e)[1])


def _fill_rigid(elements, index: np.ndarray, matrices: np.ndarray) -> None:
    """U0 and U2 of the rigid bodies ``index[:, 0]`` into ``matrices[index[:, 1]]`` and ``[index[:, 2]]``."""
    bodies = [elements[e] for e in index[:, 0].tolist()]
    records = [body.record for body in bodies]
    kinematic, inertial = rigid_transfer_parts(
        np.array([r.mass for r in records], dtype=float), np.array([r.com for r in records], dtype=float),
        np.array([r.inertia for r in records], dtype=float),
        np.array([body.ports[body.inputs[0]].position for body in bodies], dtype=float),
        np.array([body.ports[body.output].position for body in bodies], dtype=float))
    matrices[index[:, 1]] = kinematic
    matrices[index[:, 2]] = inertial


def _fill_springs(elements, index: np.ndarray, matrices: np.ndarray) -> None:
    """U0 of the springs ``index[:, 0]`` into ``matrices[index[:, 1]]``."""
    records = [elements[e].record for e in index[:, 0].tolist()]
    releases = [record.release for record in records]
    released = None if all(release is None for release in releases) else np.array(  # None: 1 / k, as nothing released
        [_NOTHING_RELEASED if release is None else release for release in releases])
    matrices[index[:, 1]] = spring_constant_transfer(np.array([r.k for r in records], dtype=float),
                                                     np.array([r.axes for r in records], dtype=float), released)


#: A spring's release where nothing is released, among others' (:func:`_fill_springs`).
_NOTHING_RELEASED = np.zeros(6, dtype=bool)


def _fill_other_inputs(elements, index: np.ndarray, matrices: np.ndarray) -> None:
    """U_{j,Ik} and H_{j,Ik} of input k + 2 of element e, for each (e, k, U index, H index) of
    ``index`` (H's rows 6: are the zeros ``matrices`` holds there, see :meth:`Constants.fill`)."""
    bodies = [elements[e] for e in index[:, 0].tolist()]
    position = np.array([[body.ports[body.inputs[0]].position, body.ports[body.inputs[k + 1]].position,
                          body.ports[body.output].position] for body, k in zip(bodies, index[:, 1].tolist())],
                        dtype=float)
    matrices[index[:, 2]] = force_extraction(position[:, 1], position[:, 2])
    matrices[index[:, 3], :6] = position_incidence(position[:, 0], position[:, 1])


def padded(matrix) -> np.ndarray:
    """``matrix`` (at most 12 × 12) in the top left corner of a float (12, 12) of zeros."""
    out = np.zeros((12, 12))
    matrix = np.asarray(matrix, dtype=float)
    out[:matrix.shape[0], :matrix.shape[1]] = matrix
    return out
