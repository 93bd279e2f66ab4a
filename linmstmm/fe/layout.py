"""Degrees of freedom of a meshed model: node numbering, positions and frames,
the growing sparse triplets the assembly writes into, and a spring's elongation
as a row on those DOFs."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

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
    """Nodes of a meshed model: numbering, positions (m) and local frames."""

    index: DofIndex
    positions: np.ndarray   # (n_nodes, 3)
    frames: np.ndarray      # (n_nodes, 3, 3) rows = the node's DOF axes

    @property
    def n_nodes(self):
        return len(self.positions)


def _layout(model: Model, elements_per_beam: int) -> _Layout:
    """Number the nodes: points, rigid mass centres, interior beam nodes."""
    points = {name: i for i, name in enumerate(model.points)}
    positions = [np.asarray(x, float) for x in model.points.values()]
    frames = [np.eye(3)] * len(positions)
    rigids = {}
    for body in model.rigids:
        rigids[body.name] = len(positions)
        positions.append(np.asarray(body.com, float))
        frames.append(np.eye(3))
    beam_nodes = {}
    n = elements_per_beam
    for beam in model.beams:
        a, b = (points[end] for end in beam.ends)
        interior = len(positions) + np.arange(n - 1)
        beam_nodes[beam.name] = np.concatenate([[a], interior, [b]])
        xa, xb = positions[a], positions[b]
        positions.extend(xa + (xb - xa) * (j / n) for j in range(1, n))
        frames.extend([np.asarray(beam.axes, float)] * (n - 1))
    return _Layout(DofIndex(points, rigids, beam_nodes),
                   np.array(positions).reshape(-1, 3),
                   np.array(frames).reshape(-1, 3, 3))


class _Triplets:
    """Growing COO lists (rows, cols, values) of one sparse matrix."""

    def __init__(self):
        self.rows, self.cols, self.values = [], [], []
        self.n_rows = 0

    def add(self, rows, cols, values):
        rows, cols, values = np.broadcast_arrays(rows, cols, values)
        self.rows.append(rows.ravel())
        self.cols.append(cols.ravel())
        self.values.append(values.ravel().astype(float))

    def new_rows(self, count):
        """Indices of ``count`` fresh rows."""
        first = self.n_rows
        self.n_rows += count
        return np.arange(first, first + count)

    def extend(self, other: "_Triplets"):
        """Append the rows of ``other`` after these (renumbered)."""
        for rows, cols, values in zip(other.rows, other.cols, other.values):
            self.add(rows + self.n_rows, cols, values)
        self.n_rows += other.n_rows

    def matrix(self, n_cols, n_rows=None) -> sp.csr_matrix:
        n_rows = self.n_rows if n_rows is None else n_rows
        if not self.rows:
            return sp.csr_matrix((n_rows, n_cols))
        coo = sp.coo_matrix((np.concatenate(self.values),
                             (np.concatenate(self.rows), np.concatenate(self.cols))),
                            shape=(n_rows, n_cols))
        matrix = coo.tocsr()
        matrix.eliminate_zeros()
        return matrix


def _spring_directions(spring, index: DofIndex, kept_only: bool):
    """(component, cols (6,), values (6,)) per direction of ``spring``: the elongation
    (end b − end a along the spring's axis, m or rad) as a row on the full DOFs of ``index``.
    kept_only : leave out the released directions."""
    a, b = (_node_dofs(index.points[end]) for end in spring.ends)
    cols = (np.concatenate([a[:3], b[:3]]), np.concatenate([a[3:], b[3:]]))
    axes = np.asarray(spring.axes, float)
    values = np.concatenate([-axes, axes], axis=1)          # row i: direction i at a, then at b
    skipped = set(spring.released.tolist()) if kept_only else set()
    for component in range(6):
        if component not in skipped:
            yield component, cols[component // 3], values[component % 3]
