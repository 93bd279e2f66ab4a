"""Zero-frequency motions counted structurally: every segment of the model moves
rigidly as far as boundaries and joints allow; the massive ones, M-orthonormal,
are the rigid-body modes, and as many statically determinate supports stop them."""
from __future__ import annotations

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from linmstmm.fe.constraints import NEGLIGIBLE_ENTRY, REDUNDANT_CONSTRAINT
from linmstmm.fe.layout import _spring_directions
from linmstmm.fe.masses import MASSLESS


def _components(model, layout, through_joints: bool = True) -> np.ndarray:
    """(n_nodes,) label of the connected part of the model each node is in.

    through_joints : False to leave out springs with a released direction (the
    parts are then the segments that move rigidly in a zero-energy motion).
    """
    edges = []
    for body in model.rigids:
        centre = layout.index.rigids[body.name]
        edges.extend((centre, layout.index.points[p]) for p in body.ports)
    for spring in model.springs:
        if through_joints or not spring.released.size:
            edges.append(tuple(layout.index.points[e] for e in spring.ends))
    for nodes in layout.index.beam_nodes.values():
        edges.extend(zip(nodes[:-1], nodes[1:]))
    edges = np.array(edges, dtype=int).reshape(-1, 2)
    graph = sp.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                          shape=(layout.n_nodes, layout.n_nodes))
    return connected_components(graph, directed=False)[1]


def _rigid_field(positions, frames, segments) -> tuple[np.ndarray, float]:
    """(6 n, 6 s) DOFs of n nodes under the unit translations and rotations of each of
    their s segments (``segments`` (n,) numbers them 0..s−1), and the scale of the rotations.

    Rotations are about the nodes' centroid and scaled by their extent, so
    translations and rotations weigh alike; each node's DOFs are in its frame.
    Nodes that coincide to rounding (an extent below NEGLIGIBLE_ENTRY of their
    coordinates: the rounding of the centroid) have no arm, and any scale
    weighs the two alike.
    """
    arm = positions - positions.mean(axis=0)
    size = np.abs(arm).max()
    if size <= NEGLIGIBLE_ENTRY * np.abs(positions).max():
        arm, size = np.zeros_like(arm), 1.0
    field = np.zeros((len(positions), 6, 6))
    for k, unit in enumerate(np.eye(3)):
        field[:, :3, k] = frames @ unit
        field[:, :3, 3 + k] = (frames @ np.cross(unit, arm)[:, :, None])[:, :, 0] / size
        field[:, 3:, 3 + k] = frames @ unit / size
    placed = np.zeros((len(positions), 6, 6 * (segments.max() + 1)))
    for node, segment in enumerate(segments):
        placed[node, :, 6 * segment:6 * segment + 6] = field[node]
    return placed.reshape(6 * len(positions), -1), float(size)


def _across_segments(spring, layout, segments) -> bool:
    """Whether ``spring`` joins two segments (joined within one, its ends move alike
    under every rigid motion of it, to the tolerance within which they coincide)."""
    a, b = (layout.index.points[end] for end in spring.ends)
    return segments[a] != segments[b]


def _rigid_motions(model, layout) -> tuple[np.ndarray, np.ndarray]:
    """(n_full, r) zero-energy motions of each connected part: every segment
    (:func:`_components` without joints) moves rigidly, as far as the boundaries and
    the directions each joint keeps allow; and (n_full,) the weight of each DOF.

    Ports, springs and rigid axial/torsion all hold under a segment's rigid
    motion; across a joint the two segments must move alike in each direction
    it keeps. The weights are 1 on translations (m) and the part's extent (m) on
    rotations (rad), so that weighted, both are lengths of the part's own scale;
    the columns are orthonormal weighted. Orthonormalised unweighted, a model in
    km (mm) would carry the rounding of its rotations (translations) into the
    other DOFs a thousand times larger, and the stiff beams' strains of these
    motions with it (a model in km lost 1e-3 of its frequencies on fine meshes).
    """
    labels = _components(model, layout)
    segments = _components(model, layout, through_joints=False)
    directions = [(np.array([dof]), np.ones(1))  # (columns, values) of each held direction
                  for point, components in model.boundary.items()
                  for dof in layout.index.point(point)[np.asarray(components, bool)]]
    directions += [(cols, values)
                   for spring in model.springs if spring.released.size and _across_segments(spring, layout, segments)
                   for _, cols, values in _spring_directions(spring, layout.index, kept_only=True)]
    held = _rows_matrix(directions, 6 * layout.n_nodes)
    motions, weights = [], np.ones(6 * layout.n_nodes)
    for label in np.unique(labels):
        nodes = np.flatnonzero(labels == label)
        dofs = (6 * nodes[:, None] + np.arange(6)).ravel()
        field, size = _rigid_field(layout.positions[nodes], layout.frames[nodes],
                                   np.unique(segments[nodes], return_inverse=True)[1])
        weight = np.tile(np.r_[np.ones(3), np.full(3, size)], len(nodes))  # rotation rows of order one
        weights[dofs] = weight
        rows = held[:, dofs]
        rows = rows[np.flatnonzero(np.diff(rows.tocsr().indptr))]  # the rows on this part
        allowed = (la.null_space(rows @ (weight[:, None] * field), rcond=REDUNDANT_CONSTRAINT)
                   if rows.shape[0] else np.eye(field.shape[1]))
        if allowed.shape[1]:
            motion = np.zeros((6 * layout.n_nodes, allowed.shape[1]))
            motion[dofs] = la.orth(weight[:, None] * (field @ allowed)) / weight[:, None]
            motions.append(motion)
    return (np.hstack(motions) if motions else np.zeros((6 * layout.n_nodes, 0))), weights


def _rows_matrix(rows, width: int) -> sp.csc_matrix:
    """(len(rows), width) sparse matrix of ``rows``, each (columns, values): built at once,
    not stacked from a matrix per row (which took most of an assembly of the launcher)."""
    if not rows:
        return sp.csc_matrix((0, width))
    columns = np.concatenate([cols for cols, _ in rows])
    values = np.concatenate([vals for _, vals in rows])
    row_of = np.repeat(np.arange(len(rows)), [cols.size for cols, _ in rows])
    return sp.csc_matrix((values, (row_of, columns)), shape=(len(rows), width))


def _rigid_basis(motions, M, weight):
    """Massive rigid-body modes (M-orthonormal) and supports that stop all motions.

    motions : (n_dof, r) rigid motions in reduced DOFs.
    weight : (n_dof,) DOF weights of :func:`_rigid_motions` (1 on translations, a
        length on rotations): the basis is orthonormalised and the kinetic energies
        are compared weighted, so neither depends on the units of the model.

    Returns
    -------
    modes : (n_dof, r_massive) with ``modes.T @ M @ modes = I``.
    supports : (r,) DOFs on which the motions are independent (pivoted QR).
    """
    n = M.shape[0]
    if motions.shape[1] == 0:
        return np.zeros((n, 0)), np.zeros(0, dtype=int)
    weighted = la.orth(weight[:, None] * motions)
    basis = weighted / weight[:, None]
    kinetic, directions = la.eigh(basis.T @ (M @ basis))
    # against the model's own mass scale too: a joint can leave a motion of massless
    # points alone, whose kinetic energy is the rounding of the others' DOFs
    massive = kinetic > MASSLESS * max(np.abs(kinetic).max(), (M.diagonal() / weight ** 2).max())
    modes = basis @ (directions[:, massive] / np.sqrt(kinetic[massive]))
    pivots = la.qr(weighted.T, pivoting=True, mode="r")[1]
    return modes, np.sort(pivots[:basis.shape[1]])
