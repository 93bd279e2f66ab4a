"""Degrees of freedom of a meshed model: node numbering, positions and frames,
the growing sparse triplets the assembly writes into, and a spring's elongation
as a row on those DOFs."""
from __future__ import annotations

import sys
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from linmstmm.fe.sparse import (
    Compressed,
    compressed_of_distinct,
    compressed_of_summed,
    scipy_csr,
)
from linmstmm.model import Model


@dataclass(frozen=True, eq=False)
class DofIndex:
    """Where each node sits in the full DOF vector.

    The full vector holds six DOFs per node, node after node: first the model
    points (in ``model.points`` order), then the rigid-body mass centres (in
    ``model.rigids`` order), then the interior nodes of each beam (beam after
    beam, from end a to end b). Point and mass-centre DOFs are
    ``(ux, uy, uz, θx, θy, θz)`` in the inertial frame; interior beam nodes are
    in that beam's local axes (rows of ``Beam.axes``), see
    :meth:`FEModel.beam_motion`.

    points, rigids : name -> node number. beam_nodes : name -> (n+1,) node
    numbers from end a to end b, ends included.
    """

    points: dict
    rigids: dict
    beam_nodes: dict

    def point(self, name: str) -> np.ndarray:
        """(6,) full-vector indices of point ``name``."""
        return _node_dofs(self.points[name])

    def rigid(self, name: str) -> np.ndarray:
        """(6,) full-vector indices of the mass centre of rigid body ``name``."""
        return _node_dofs(self.rigids[name])

    def beam(self, name: str) -> np.ndarray:
        """(n+1, 6) full-vector indices of the nodes of beam ``name``."""
        return 6 * self.beam_nodes[name][:, None] + np.arange(6)


def _node_dofs(node):
    return 6 * node + np.arange(6)


@dataclass(frozen=True, eq=False)
class _Layout:
    """Nodes of a meshed model: numbering, positions (m) and local frames.

    beam_table : (n_beams, n+1) the nodes of each beam (``model.beams`` order), end a
        to end b, as in ``index.beam_nodes``.
    beam_axes : (n_beams, 3, 3) rows = each beam's local axes in the inertial frame.
    """

    index: DofIndex
    positions: np.ndarray   # (n_nodes, 3)
    frames: np.ndarray      # (n_nodes, 3, 3) rows = the node's DOF axes
    beam_table: np.ndarray
    beam_axes: np.ndarray

    @property
    def n_nodes(self):
        return len(self.positions)


def _layout(model: Model, elements_per_beam: int, nodes: _Layout | None = None) -> _Layout:
    """Number the nodes: points, rigid mass centres, interior beam nodes. ``nodes``: the
    layout of ``model`` with one element per beam (its points and mass centres, which
    every mesh numbers first), to add the interior nodes to; made here by default."""
    n = elements_per_beam
    if nodes is None:
        points = {name: i for i, name in enumerate(model.points)}
        rigids = {body.name: len(points) + i for i, body in enumerate(model.rigids)}
        placed = np.array([*model.points.values(), *(body.com for body in model.rigids)], float).reshape(-1, 3)
        ends = np.array([[points[end] for end in beam.ends] for beam in model.beams], int).reshape(-1, 2)
        axes = _beam_axes(model.beams)
    else:
        points, rigids, placed, ends, axes = (nodes.index.points, nodes.index.rigids, nodes.positions,
                                              nodes.beam_table, nodes.beam_axes)
        if n == 1:
            return nodes
    if n == 1:  # no interior node: the points and mass centres as they are
        return _Layout(DofIndex(points, rigids, {beam.name: nodes for beam, nodes in zip(model.beams, ends)}),
                       placed, np.repeat(_INERTIAL[None], len(placed), axis=0), ends, axes)
    interior = len(placed) + np.arange(len(ends) * (n - 1)).reshape(len(ends), n - 1)
    table = np.concatenate([ends[:, :1], interior, ends[:, 1:]], axis=1)
    xa, xb = placed[ends[:, 0]], placed[ends[:, 1]]
    inside = xa[:, None] + (xb - xa)[:, None] * (np.arange(1, n) / n)[None, :, None]
    frames = np.concatenate([np.broadcast_to(_INERTIAL, (len(placed), 3, 3)), np.repeat(axes, n - 1, axis=0)])
    return _Layout(DofIndex(points, rigids, {beam.name: nodes for beam, nodes in zip(model.beams, table)}),
                   np.concatenate([placed, inside.reshape(-1, 3)]), frames, table, axes)


#: The axes of a point's or mass centre's DOFs (rows): the inertial ones.
_INERTIAL = np.eye(3)
_INERTIAL.setflags(write=False)


def _beam_axes(beams) -> np.ndarray:
    """(n_beams, 3, 3) rows = each beam's local axes in the inertial frame."""
    return np.array([beam.axes for beam in beams], float).reshape(-1, 3, 3)


def compiled_nodes() -> bool:
    """Whether the node constraints (the elimination T of :mod:`linmstmm.fe.port_following`,
    the springs' and bodies' entries of :mod:`linmstmm.fe.node_constraints`) and the
    elements' maps (:func:`element_maps`) are made by :mod:`linmstmm._node_kernels`:
    where the compiled kernels are loaded already (:func:`linmstmm.determinant.kernels_loaded`,
    asked only where that module is loaded: the FE route alone loads neither it nor
    numba). The same arrays as in numpy either way.

    Returns
    -------
    bool
    """
    determinant = sys.modules.get("linmstmm.determinant")
    return determinant is not None and determinant.kernels_loaded()


def element_maps(nodes: np.ndarray, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Full DOFs of the elements of b beams and the maps to each element's local DOFs.

    Parameters
    ----------
    nodes : (b, n+1) each beam's nodes, end a to end b (:attr:`_Layout.beam_table`).
    axes : (b, 3, 3) rows = each beam's local axes.

    Returns
    -------
    dofs : (b, n, 12) the element's full DOFs, node 1 then node 2.
    to_local : (b, n, 12, 12) maps from those DOFs to the element's local ones: the
        end nodes' DOFs are inertial (rotated by ``axes``), interior ones local already.
    """
    if compiled_nodes():
        from linmstmm._node_kernels import element_entries

        return element_entries(nodes, axes)
    return _element_maps_in_numpy(nodes, axes)


def _element_maps_in_numpy(nodes: np.ndarray, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`element_maps` in numpy: the readable reference of
    :func:`linmstmm._node_kernels.element_entries`."""
    b, n = nodes.shape[0], nodes.shape[1] - 1
    to_local = np.zeros((b, n, 12, 12))
    to_local[:, :, np.arange(12), np.arange(12)] = 1.0
    for block in (0, 3):
        to_local[:, 0, block:block + 3, block:block + 3] = axes
        to_local[:, -1, 6 + block:9 + block, 6 + block:9 + block] = axes
    dofs = 6 * np.stack([nodes[:, :-1], nodes[:, 1:]], axis=2)[..., None] + np.arange(6)
    return dofs.reshape(b, n, 12), to_local


class _Triplets:
    """Growing COO lists (rows, cols, values) of one sparse matrix.

    repeats : True where entries may fall on the same position (mass blocks that
    share a node) and are summed; False where each position is written once
    (strain and constraint rows), and the matrix is built without summing.
    """

    def __init__(self, repeats: bool = False):
        self.rows, self.cols, self.values = [], [], []
        self.n_rows = 0
        self.repeats = repeats
        self._joined = None   # joined(), made on first use, dropped when entries are added

    def add(self, rows, cols, values):
        """Add the entries ``values`` at (``rows``, ``cols``), the three broadcast together."""
        if _flat_alike(rows, cols, values):  # flat already (as the compiled node builder writes them)
            self._append(rows, cols, values.astype(float, copy=False))
            return
        shape = np.broadcast(rows, cols, values).shape
        rows, cols, values = (_flat(part, shape) for part in (rows, cols, values))
        self._append(rows, cols, values.astype(float, copy=False))

    def _append(self, rows, cols, values):
        """Append flat entries as they are."""
        self.rows.append(rows)
        self.cols.append(cols)
        self.values.append(values)
        self._joined = None

    def joined(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rows, cols, values) of every entry, (nnz,) int64, int64 and float64: made
        once until more entries are added, and shared (never written), so that the
        counter and the coarse pencil of one model join them once."""
        if self._joined is None:
            self._joined = tuple(_joined(part, dtype) for part, dtype in ((self.rows, np.int64), (self.cols, np.int64),
                                                                          (self.values, float)))
        return self._joined

    def new_rows(self, count):
        """Indices of ``count`` fresh rows."""
        first = self.n_rows
        self.n_rows += count
        return np.arange(first, first + count)

    def copy(self) -> _Triplets:
        """A twin to add to: the same entries (arrays shared, never written), its own lists."""
        twin = _Triplets(self.repeats)
        twin.rows, twin.cols, twin.values = list(self.rows), list(self.cols), list(self.values)
        twin.n_rows = self.n_rows
        return twin

    def extend(self, other: "_Triplets"):
        """Append the rows of ``other`` after these (renumbered)."""
        for rows, cols, values in zip(other.rows, other.cols, other.values):
            self._append(rows + self.n_rows, cols, values)
        self.n_rows += other.n_rows

    def matrix(self, n_cols, n_rows=None) -> sp.csr_matrix:
        """(n_rows, n_cols) canonical CSR of the entries, zeros dropped (summed first
        where they repeat, in scipy's order); ``n_rows`` defaults to the rows numbered."""
        return scipy_csr(self.compressed(n_cols, n_rows))

    def compressed(self, n_cols, n_rows=None) -> Compressed:
        """:meth:`matrix` as :class:`~linmstmm.fe.sparse.Compressed` rows (no scipy object)."""
        n_rows = self.n_rows if n_rows is None else n_rows
        if not self.rows:
            return Compressed("csr", np.zeros(n_rows + 1, int), np.zeros(0, int), np.zeros(0), (n_rows, n_cols))
        rows, cols, values = self.joined()
        if self.repeats:
            return compressed_of_summed(rows, cols, values, (n_rows, n_cols))
        nonzero = values != 0
        return compressed_of_distinct(rows[nonzero], cols[nonzero], values[nonzero], (n_rows, n_cols))


def _joined(parts: list, dtype) -> np.ndarray:
    """The arrays ``parts`` end to end as ``dtype``: a lone one as it is where it has that type."""
    if len(parts) == 1:
        return parts[0].astype(dtype, copy=False)
    return np.concatenate(parts).astype(dtype, copy=False) if parts else np.zeros(0, dtype)


def _flat_alike(*parts) -> bool:
    """Whether ``parts`` are all one-dimensional arrays of one length."""
    first = parts[0]
    return all(isinstance(part, np.ndarray) and part.ndim == 1 and len(part) == len(first) for part in parts)


def _flat(part, shape: tuple) -> np.ndarray:
    """``part`` broadcast to ``shape`` and flattened (its own flat view where it has that shape)."""
    part = np.asarray(part)
    return part.ravel() if part.shape == shape else np.broadcast_to(part, shape).ravel()


def _spring_directions(spring, index: DofIndex, kept_only: bool):
    """(component, cols (6,), values (6,)) per direction of ``spring``: the elongation
    (end b − end a along the spring's axis, m or rad) as a row on the full DOFs of ``index``.
    kept_only : leave out the released directions."""
    _, components, cols, values = spring_rows((spring,), index, kept_only)
    yield from zip(components.tolist(), cols, values)


def spring_rows(springs, index: DofIndex, kept_only: bool):
    """Every direction of ``springs`` as a row on the full DOFs of ``index``: the
    elongation, end b − end a along the spring's axis (m or rad).

    Parameters
    ----------
    springs : sequence of s :class:`~linmstmm.model.Spring`.
    index : where their end points sit.
    kept_only : leave out the released directions.

    Returns
    -------
    owners : (d,) the spring of each row (its position in ``springs``).
    components : (d,) its direction, 0..5 (x, y, z, rx, ry, rz in the spring's axes).
    cols : (d, 6) full DOFs of the row: three at end a, then three at end b.
    values : (d, 6) its entries, −axis at end a, +axis at end b.
    Rows are in the springs' order, each spring's in ascending direction.
    """
    points = index.points
    ends = np.array([(points[spring.ends[0]], points[spring.ends[1]]) for spring in springs], int).reshape(-1, 2)
    cols = (6 * ends[:, None, :, None] + _DIRECTION_DOFS).reshape(-1, 6, 6)        # (s, 6, 2 ends × 3)
    axes = np.array([spring.axes for spring in springs], float).reshape(-1, 3, 3)[:, [0, 1, 2, 0, 1, 2]]
    values = np.concatenate([-axes, axes], axis=2)                                # (s, 6, 6)
    released = [i for i, spring in enumerate(springs) if spring.release is not None] if kept_only else []
    if not released:                                                              # every direction kept
        return np.repeat(np.arange(len(ends)), 6), np.tile(np.arange(6), len(ends)), cols.reshape(-1, 6), \
            values.reshape(-1, 6)
    kept = np.ones((len(ends), 6), bool)
    kept[released] = ~np.array([springs[i].release for i in released], bool).reshape(-1, 6)
    owners, components = np.nonzero(kept)
    return owners, components, cols[kept], values[kept]


#: The DOFs of a spring's row per direction (x, y, z, rx, ry, rz), (6, 1, 3): three at
#: each end, translations or rotations, offset by 6 × the end's node.
_DIRECTION_DOFS = (np.array([0, 0, 0, 3, 3, 3])[:, None] + np.arange(3))[:, None, :]
