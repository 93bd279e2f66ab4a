"""Mode shapes of the transfer matrix method against the finite-element route's.

:func:`fe_mac` computes the modal assurance criterion (MAC) between the
elastic modes of a :class:`~linmstmm.modes.ModalResult` and the modes of
:func:`linmstmm.fe.fe_frequencies` on the same model, at the points' six
degrees of freedom. Within a repeated frequency any basis of the eigenspace
is a valid set of modes, so the FE basis is first turned towards ours
(:func:`align_eigenspaces`).
"""
from __future__ import annotations

import numpy as np

from linmstmm.model import Model, ModelError
from linmstmm.modes import ModalResult, mac_matrix

#: Frequencies closer than this (relative) are one repeated frequency when
#: eigenspaces of the FE route are aligned for the MAC.
REPEATED = 1e-6


def fe_mac(result: ModalResult, model: Model) -> tuple[np.ndarray, np.ndarray]:
    """MAC of the elastic modes of ``result`` against the finite-element route's modes.

    Parameters
    ----------
    result : ModalResult
        Modes of ``model`` by :func:`linmstmm.modes.mode_shapes`.
    model : Model
        The model they belong to.

    Returns
    -------
    fe_frequencies_hz : numpy.ndarray, shape (m,)
        The FE route's elastic natural frequencies, Hz (m = elastic modes of ``result``).
    mac : numpy.ndarray, shape (n, m)
        MAC between our n elastic modes and the FE modes, in [0, 1], taken
        at every point's six degrees of freedom; within a repeated frequency
        the FE basis is aligned to ours first (:func:`align_eigenspaces`).

    Raises
    ------
    ModelError
        If ``result`` holds no elastic mode.
    """
    from linmstmm.fe.assembly import assemble
    from linmstmm.fe.frequencies import fe_frequencies

    elastic = result.omega > 0
    if not elastic.any():
        raise ModelError(model.source or model.name, "no elastic mode among the modes to compare with "
                         "the finite-element route")
    fe = fe_frequencies(model, count=int(elastic.sum()), mode_shapes=True)
    index = assemble(model, 1).dof_index  # point DOFs come first, whatever the mesh
    dofs = np.concatenate([index.point(point) for point in model.points])
    ours = result.shape_matrix(model.points)[elastic]
    theirs = align_eigenspaces(ours, fe.mode_shapes[dofs].T, fe.frequencies_hz)
    return fe.frequencies_hz, mac_matrix(ours, theirs)


def align_eigenspaces(reference: np.ndarray, shapes: np.ndarray, frequencies_hz) -> np.ndarray:
    """Turn each repeated frequency's basis of ``shapes`` towards ``reference``.

    A repeated frequency's modes are any basis of its eigenspace; the MAC of
    two such bases says nothing. Mode i of a group (indices in
    ``frequencies_hz``, equal within REPEATED) is replaced by the projection
    of reference mode i onto the group's span, so its MAC with reference mode
    i measures how far that mode lies outside the eigenspace.

    Parameters
    ----------
    reference : numpy.ndarray, shape (n, d)
        The shapes to align to.
    shapes : numpy.ndarray, shape (m, d)
        The shapes to align, ascending in frequency.
    frequencies_hz : array_like, shape (m,)
        The natural frequencies of ``shapes``, Hz, ascending.

    Returns
    -------
    numpy.ndarray, shape (m, d)
        ``shapes`` with every repeated frequency's basis aligned.
    """
    aligned = np.array(shapes, dtype=float)
    for group in _repeated_groups(np.asarray(frequencies_hz, dtype=float)):
        group = group[group < len(reference)]
        basis = shapes[group].T
        aligned[group] = (basis @ np.linalg.lstsq(basis, reference[group].T, rcond=None)[0]).T
    return aligned


def _repeated_groups(frequencies: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the runs of two or more equal frequencies (ascending input)."""
    starts = np.flatnonzero(np.r_[True, np.diff(frequencies) > REPEATED * frequencies[1:]])
    runs = np.split(np.arange(frequencies.size), starts[1:])
    return [run for run in runs if run.size > 1]
