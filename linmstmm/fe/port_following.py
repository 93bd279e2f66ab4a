"""The constraint elimination of a model whose only constraints are fixed components
of points no rigid body owns: every port follows its body's mass centre, every
fixed component is dropped, every other DOF is kept as it is.

Where each entry of that elimination T sits, and which number it takes, is fixed
by the model's structure (its points, bodies, ports and boundary); only the
numbers, the ports' lever arms, come from where the nodes sit. A
:class:`PortFollowing` holds the first and puts the second into it. One is kept
per structure (:func:`kept_port_following`): the node constraints
(:func:`linmstmm.fe.node_constraints.node_constraints`) and the Wittrick–Williams
counter's parts (:mod:`linmstmm.counter_parts`) make every model's T with it, the
same arrays.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.fe.layout import compiled_nodes
from linmstmm.fe.sparse import Compressed, index_type
from linmstmm.model import Model
from linmstmm.model_structure import MODELS_KEPT, KeptByStructure


@dataclass(frozen=True, eq=False)
class PortFollowing:
    """Where each possible entry of the elimination T sits and where its number comes from.

    Attributes
    ----------
    arm_ends, arm_starts, arm_signs : numpy.ndarray, shape (6 p,)
        Each port's six lever-arm entries (:data:`ARM_SLOTS`, bodies and ports in model
        order): where the port's and its body's mass centre's coordinate sit in the
        flattened positions, and the sign the difference takes.
    rows, cols : numpy.ndarray, shape (e,)
        Row (full DOF) and column (reduced DOF) of each possible entry: rows ascending,
        within a port's row the columns descending (the order scipy's product of the
        general elimination stores them in).
    source : numpy.ndarray, shape (e,)
        Where each entry's number comes from among 1, 0 and then the ports' lever-arm
        entries (``arm_ends``): 0 a unit entry, 1 a zero one, 2 + 6 i + j the j-th
        lever-arm entry of port i (:data:`ARM_SLOTS`).
    masters : numpy.ndarray, shape (n_dof,)
        The full DOFs kept as the reduced ones, ascending.
    shape : tuple
        (n_full, n_dof).
    """

    arm_ends: np.ndarray
    arm_starts: np.ndarray
    arm_signs: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    source: np.ndarray
    masters: np.ndarray
    shape: tuple

    def T(self, positions: np.ndarray) -> Compressed:
        """The elimination of a model whose nodes sit at ``positions``.

        Parameters
        ----------
        positions : numpy.ndarray, shape (n_nodes, 3)
            m, the points then the mass centres (:class:`~linmstmm.fe.layout._Layout`).

        Returns
        -------
        Compressed
            (n_full, n_dof) CSR: the arrays scipy's product T0 T1 of the general
            elimination stores (exact zeros left out, a fixed component's row
            empty), indices of the type scipy gives them
            (:func:`~linmstmm.fe.sparse.index_type`).
        """
        if compiled_nodes():
            from linmstmm._node_kernels import following_entries

            return self.compressed(*following_entries(positions.ravel(), self.arm_ends, self.arm_starts,
                                                      self.arm_signs, self.rows, self.cols, self.source,
                                                      self.shape[0]))
        return self._T_in_numpy(positions)

    def compressed(self, indptr: np.ndarray, indices: np.ndarray, data: np.ndarray) -> Compressed:
        """T of the CSR arrays :func:`linmstmm._node_kernels.following_entries` makes
        ((n_full + 1,), (nnz,) int64 and (nnz,) float64), its indices of the type scipy
        gives them (:func:`~linmstmm.fe.sparse.index_type`)."""
        index = index_type(self.shape[1], len(data))
        return Compressed("csr", indptr.astype(index), indices.astype(index), data, self.shape)

    def _T_in_numpy(self, positions: np.ndarray) -> Compressed:
        """:meth:`T` in numpy: the readable reference of :func:`linmstmm._node_kernels.following_entries`."""
        flat = positions.ravel()
        arms = (flat[self.arm_ends] - flat[self.arm_starts]) * self.arm_signs
        values = np.concatenate([[1.0, 0.0], arms])[self.source]
        stored = values != 0
        data = values[stored]
        index = index_type(self.shape[1], len(data))
        indptr = np.zeros(self.shape[0] + 1, index)
        np.cumsum(np.bincount(self.rows[stored], minlength=self.shape[0]), out=indptr[1:])
        return Compressed("csr", indptr, self.cols[stored].astype(index, copy=False), data, self.shape)


#: The layout of T of each structure seen last (:func:`kept_port_following`).
_followings = KeptByStructure(MODELS_KEPT)


def kept_port_following(model: Model, layout, made: PortFollowing | None = None) -> PortFollowing:
    """The :func:`port_following` of ``model`` on ``layout``, made for the first model
    of its structure and kept for the next (it depends on the structure alone).

    Parameters
    ----------
    model : Model
    layout : linmstmm.fe.layout._Layout
        As for :func:`port_following`.
    made : PortFollowing, optional
        The model's, made already (by :func:`linmstmm._node_kernels.held_nodes`): kept
        where none is, instead of making it.

    Returns
    -------
    PortFollowing
        The same object for every model of the structure.
    """
    return _followings.get(model, lambda model: port_following(model, layout) if made is None else made)


def port_following(model: Model, layout) -> PortFollowing:
    """The :class:`PortFollowing` of ``model`` laid out on ``layout`` (its points and
    mass centres, :func:`~linmstmm.fe.layout._layout` with one element per beam).

    Parameters
    ----------
    model : Model
        A model whose every constraint is a fixed component of a point no body owns
        (:func:`~linmstmm.fe.node_constraints.held_at_free_points`).
    layout : linmstmm.fe.layout._Layout

    Returns
    -------
    PortFollowing
    """
    n_full, nodes = 6 * layout.n_nodes, following_nodes(model, layout)
    if compiled_nodes():
        from linmstmm._node_kernels import following_layout

        return followed(n_full, following_layout(n_full, *nodes, *FOLLOWING_CONSTANTS))
    return followed(n_full, _following_in_numpy(n_full, *nodes))


def following_nodes(model: Model, layout) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(port_nodes (p,), centre_nodes (p,), boundary_nodes (f,), fixed (f, 6) bool): each
    port's node and its body's mass centre's (bodies and ports in model order), the
    boundary's points' nodes and their fixed components, on ``layout``: what
    :func:`port_following` is made of."""
    index = layout.index
    port_nodes = np.array([index.points[port] for body in model.rigids for port in body.ports], int)
    centre_nodes = np.array([index.rigids[body.name] for body in model.rigids for _ in body.ports], int)
    boundary_nodes = np.array([index.points[point] for point in model.boundary], int)
    fixed = np.array([components for components in model.boundary.values()], bool).reshape(-1, 6)
    return port_nodes, centre_nodes, boundary_nodes, fixed


def followed(n_full: int, arrays: tuple) -> PortFollowing:
    """The :class:`PortFollowing` of (arm_ends, arm_starts, arm_signs, rows, cols, source,
    masters) on ``n_full`` full DOFs."""
    return PortFollowing(*arrays, (n_full, len(arrays[-1])))


def _following_in_numpy(n_full: int, port_nodes: np.ndarray, centre_nodes: np.ndarray, boundary_nodes: np.ndarray,
                        fixed: np.ndarray) -> tuple:
    """(arm_ends, arm_starts, arm_signs, rows, cols, source, masters) of :class:`PortFollowing`
    of ports at ``port_nodes`` (p,) following their bodies' mass centres at ``centre_nodes``
    (p,), the ``fixed`` (f, 6) components of the points at ``boundary_nodes`` (f,) dropped,
    in numpy: the readable reference of :func:`linmstmm._node_kernels.following_layout`."""
    ports, centres = (6 * nodes.reshape(-1, 1) + np.arange(6) for nodes in (port_nodes, centre_nodes))
    dropped = np.zeros(n_full, bool)
    dropped[ports] = True
    dropped[(6 * boundary_nodes.reshape(-1, 1) + np.arange(6))[fixed]] = True
    masters = np.flatnonzero(~dropped)
    # each row's possible entries: a master's its unit entry, a port's its body's six
    # centre columns descending, their numbers the lever-arm block's row reversed
    column = np.cumsum(~dropped) - 1
    p = len(port_nodes)
    rows = np.concatenate([masters, np.repeat(ports.ravel(), 6)])
    cols = np.concatenate([np.arange(len(masters)), np.broadcast_to(column[centres][:, None, ::-1], (p, 6, 6)).ravel()])
    source = np.concatenate([np.zeros(len(masters), int),
                             (_BLOCK_SOURCE + 6 * np.arange(p)[:, None, None] * _ON_ARM).ravel()])
    order = np.argsort(rows, kind="stable")             # rows ascending, each row's entries in their order
    arm_ends, arm_starts = ((3 * nodes[:, None] + ARM_AXES).ravel() for nodes in (port_nodes, centre_nodes))
    return arm_ends, arm_starts, np.tile(ARM_SIGNS, p), rows[order], cols[order], source[order], masters


#: Where −[r]ₓ puts a port's lever arm r (m) in its 6 × 6 block, flattened
#: (translation rows, rotation columns), and which component of r, of which sign.
ARM_SLOTS = np.array([4, 5, 9, 11, 15, 16])
ARM_AXES = np.array([2, 1, 2, 0, 1, 0])
ARM_SIGNS = np.array([1.0, -1.0, -1.0, 1.0, 1.0, -1.0])


def _block_source() -> tuple[np.ndarray, np.ndarray]:
    """(6, 6) where each entry of the first port's lever-arm block takes its number from
    (:attr:`PortFollowing.source`), each row's columns reversed as T stores them, and
    (6, 6) 1 on the lever arms (a further port's are 6 further on), else 0."""
    block = np.ones(36, int)                                   # a zero entry
    block[::7] = 0                                             # the unit diagonal
    block[ARM_SLOTS] = 2 + np.arange(len(ARM_SLOTS))
    block = block.reshape(6, 6)[:, ::-1]
    return block, (block >= 2).astype(int)


_BLOCK_SOURCE, _ON_ARM = _block_source()

#: The constant arguments of :func:`linmstmm._node_kernels.following_layout`, in its order.
FOLLOWING_CONSTANTS = (_BLOCK_SOURCE, _ON_ARM, ARM_AXES, ARM_SIGNS)


def port_kinematics(ports: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(p, 6, 6) maps body-centre DOFs -> port DOFs: u_p = u_c + θ × (p − c), θ_p = θ.

    Parameters
    ----------
    ports, centres : numpy.ndarray, shape (p, 3)
        Positions of the ports and of their bodies' mass centres, m.

    Returns
    -------
    numpy.ndarray, shape (p, 6, 6)
        Unit diagonal; the lever arms (m) in the translations' rows, rotation columns.
    """
    block = np.zeros((len(ports), 36))
    block[:, ::7] = 1.0
    # −[r]ₓ, whose zero diagonal stays +0.0 (a −0.0 there would be dropped as any zero is)
    block[:, ARM_SLOTS] = (ports - centres)[:, ARM_AXES] * ARM_SIGNS
    return block.reshape(-1, 6, 6)
