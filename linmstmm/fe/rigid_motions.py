"""Zero-frequency motions counted structurally: every segment of the model moves
rigidly as far as boundaries and joints allow; the massive ones, M-orthonormal,
are the rigid-body modes, and as many statically determinate supports stop them."""
from __future__ import annotations

import numpy as np
import scipy.linalg as la

from linmstmm.fe.constraints import NEGLIGIBLE_ENTRY, REDUNDANT_CONSTRAINT
from linmstmm.fe.layout import spring_rows
from linmstmm.fe.masses import MASSLESS
from linmstmm.fe.sparse import scipy_csr
from linmstmm.union_find import components


def _edges(model, layout) -> tuple[np.ndarray, np.ndarray]:
    """(e, 2) the node pairs the elements join (a body's mass centre and each port, a
    spring's ends, the ends of every beam element) and (e,) bool, True for the springs
    with a released direction (joints)."""
    index = layout.index
    ports = [(index.rigids[body.name], index.points[port]) for body in model.rigids for port in body.ports]
    springs = [[index.points[end] for end in spring.ends] for spring in model.springs]
    table = layout.beam_table
    edges = np.concatenate([np.array(ports, int).reshape(-1, 2), np.array(springs, int).reshape(-1, 2),
                            np.stack([table[:, :-1].ravel(), table[:, 1:].ravel()], axis=1)])
    joints = np.zeros(len(edges), bool)
    joints[len(ports):len(ports) + len(springs)] = _released_any(model.springs)
    return edges, joints


def _released_any(springs) -> np.ndarray:
    """(s,) bool: which of ``springs`` release a direction (are joints)."""
    given = [i for i, spring in enumerate(springs) if spring.release is not None]
    joints = np.zeros(len(springs), bool)
    if given:
        joints[given] = np.array([springs[i].release for i in given], bool).reshape(len(given), 6).any(axis=1)
    return joints


def _components(edges: np.ndarray, n_nodes: int) -> np.ndarray:
    """(n_nodes,) label of the connected part each node is in, parts numbered in the
    order of their lowest node; ``edges`` (e, 2) the node pairs joined.

    Each node points at a lower one of its part (at first itself): every edge hooks
    the higher of its two ends' roots onto the lower, and pointers are followed to
    their roots, until every edge joins nodes of one root, the lowest of the part.
    """
    root = np.arange(n_nodes)
    while True:
        a, b = root[edges[:, 0]], root[edges[:, 1]]
        if (a == b).all():
            return np.unique(root, return_inverse=True)[1]
        np.minimum.at(root, np.maximum(a, b), np.minimum(a, b))
        while not (root[root] == root).all():
            root = root[root]


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
    unit = np.eye(3)[:, None, :]                                   # (3 axes, 1, 3)
    moment = np.stack([unit[..., 1] * arm[:, 2] - unit[..., 2] * arm[:, 1],   # unit × arm, as np.cross
                       unit[..., 2] * arm[:, 0] - unit[..., 0] * arm[:, 2],
                       unit[..., 0] * arm[:, 1] - unit[..., 1] * arm[:, 0]], axis=-1)
    field = np.zeros((len(positions), 6, 6))
    turned = frames + 0.0                                          # = frames @ unit k, column k (no −0)
    field[:, :3, :3] = turned
    field[:, :3, 3:] = np.moveaxis((frames @ moment[..., None])[..., 0], 0, 2) / size
    field[:, 3:, 3:] = turned / size
    placed = np.zeros((len(positions), 6, 6 * (segments.max() + 1)))
    columns = 6 * segments[:, None, None] + np.arange(6)
    placed[np.arange(len(positions))[:, None, None], np.arange(6)[:, None], columns] = field
    return placed.reshape(6 * len(positions), -1), float(size)


def _across_segments(spring, layout, segments) -> bool:
    """Whether ``spring`` joins two segments (joined within one, its ends move alike
    under every rigid motion of it, to the tolerance within which they coincide)."""
    a, b = (layout.index.points[end] for end in spring.ends)
    return segments[a] != segments[b]


def _held_directions(model, layout, segments) -> list[tuple[np.ndarray, np.ndarray]]:
    """The directions a rigid motion must hold, as blocks of rows of one width:
    (cols (k, w), values (k, w)) on the full DOFs, each row's columns ascending.
    First the fixed components of the boundaries (w = 1), then the directions each
    joint between two segments keeps (w = 6)."""
    fixed = [layout.index.point(point)[np.asarray(components, bool)] for point, components in model.boundary.items()]
    fixed = np.concatenate(fixed) if fixed else np.zeros(0, int)
    joints = tuple(spring for spring in model.springs
                   if spring.released.size and _across_segments(spring, layout, segments))
    _, _, cols, values = spring_rows(joints, layout.index, kept_only=True)
    ascending = np.argsort(cols, axis=1, kind="stable")
    return [(fixed[:, None], np.ones((len(fixed), 1))),
            (np.take_along_axis(cols, ascending, axis=1), np.take_along_axis(values, ascending, axis=1))]


def _held_rows(directions, in_part: np.ndarray, motions: np.ndarray) -> np.ndarray:
    """(k, r) the held directions on the nodes ``in_part`` ((n_nodes,) bool) applied to
    ``motions`` (6 per node of the part, r): each row summed over its columns in
    ascending order, as a sparse product does."""
    rank = np.cumsum(in_part) - 1                     # a node's place among the part's
    blocks = []
    for cols, values in directions:
        on_part = in_part[cols[:, 0] // 6]
        cols, values = cols[on_part], values[on_part]
        block = np.zeros((len(cols), motions.shape[1]))
        for col, value in zip((6 * rank[cols // 6] + cols % 6).T, values.T):
            block += value[:, None] * motions[col]
        blocks.append(block)
    return np.concatenate(blocks)


def _rigid_motions(model, layout) -> tuple[np.ndarray, np.ndarray]:
    """(n_full, r) zero-energy motions of each connected part: every segment
    (the parts :func:`_components` finds without the joints) moves rigidly, as far
    as the boundaries and the directions each joint keeps allow; and (n_full,) the
    weight of each DOF.

    Ports, springs and rigid axial/torsion all hold under a segment's rigid
    motion; across a joint the two segments must move alike in each direction
    it keeps. The weights are 1 on translations (m) and the part's extent (m) on
    rotations (rad), so that weighted, both are lengths of the part's own scale;
    the columns are orthonormal weighted. Orthonormalised unweighted, a model in
    km (mm) would carry the rounding of its rotations (translations) into the
    other DOFs a thousand times larger, and the stiff beams' strains of these
    motions with it (a model in km lost 1e-3 of its frequencies on fine meshes).
    """
    edges, joints = _edges(model, layout)
    labels = _components(edges, layout.n_nodes)
    segments = _components(edges[~joints], layout.n_nodes)
    directions = _held_directions(model, layout, segments)
    motions, weights = [], np.ones(6 * layout.n_nodes)
    for label in np.unique(labels):
        in_part = labels == label
        nodes = np.flatnonzero(in_part)
        dofs = (6 * nodes[:, None] + np.arange(6)).ravel()
        field, size = _rigid_field(layout.positions[nodes], layout.frames[nodes],
                                   np.unique(segments[nodes], return_inverse=True)[1])
        weight = np.tile(np.r_[np.ones(3), np.full(3, size)], len(nodes))  # rotation rows of order one
        weights[dofs] = weight
        rows = _held_rows(directions, in_part, weight[:, None] * field)
        allowed = la.null_space(rows, rcond=REDUNDANT_CONSTRAINT) if rows.shape[0] else np.eye(field.shape[1])
        if allowed.shape[1]:
            motion = np.zeros((6 * layout.n_nodes, allowed.shape[1]))
            motion[dofs] = la.orth(weight[:, None] * (field @ allowed)) / weight[:, None]
            motions.append(motion)
    return (np.hstack(motions) if motions else np.zeros((6 * layout.n_nodes, 0))), weights


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
    if motions.shape[1] == 0:
        return np.zeros((M.shape[0], 0)), np.zeros(0, dtype=int)
    weighted, basis, kinetic, directions, massive = _kinetic_directions(motions, M, weight)
    modes = basis @ (directions[:, massive] / np.sqrt(kinetic[massive]))
    pivots = la.qr(weighted.T, pivoting=True, mode="r")[1]
    return modes, np.sort(pivots[:basis.shape[1]])


def rigid_modes(model, layout, masters: np.ndarray, M) -> tuple[np.ndarray, np.ndarray]:
    """The rigid-body modes and supports (:func:`_rigid_basis`) of ``model`` meshed on
    ``layout``, in its reduced DOFs ``masters`` ((n_dof,) full DOFs) with (n_dof, n_dof)
    sparse mass M; none at once where every segment is clamped (:func:`_held_everywhere`)."""
    if _held_everywhere(model, layout):
        return np.zeros((M.shape[0], 0)), np.zeros(0, dtype=int)
    motions, weight = _rigid_motions(model, layout)
    return _rigid_basis(motions[masters], M, weight[masters])


def rigid_mode_count(model, layout, masters: np.ndarray, M) -> int:
    """The number of rigid-body modes :func:`rigid_modes` finds, without forming them
    or the supports.

    Parameters
    ----------
    model, layout : the model and its meshed nodes (:func:`linmstmm.fe.layout._layout`).
    masters : (n_dof,) the full DOFs kept as the reduced ones.
    M : (n_dof, n_dof) mass, kg and kg m², scipy CSR or dense (taken as the CSR of
        its nonzero entries: the same kinetic energies).

    Returns
    -------
    int
    """
    if _held_everywhere(model, layout):
        return 0
    motions, weight = _rigid_motions(model, layout)
    if motions.shape[1] == 0:
        return 0
    return int(np.count_nonzero(_kinetic_directions(motions[masters], scipy_csr(M), weight[masters])[4]))


def _held_everywhere(model, layout) -> bool:
    """Whether every segment (:func:`_rigid_motions`) has a point fixed in all six
    components. Then there is no rigid motion: weighted, each such point's six held
    rows are unit upper triangular on its segment's motions (their least singular
    value above 1/3, far above REDUNDANT_CONSTRAINT of the largest), and further
    rows only add rank.

    The segments are joined here on the points and mass centres alone (a beam's
    interior nodes lie in its ends' segment), one edge per port, spring that
    releases nothing and beam: a few dozen edges where the mesh's edge arrays and
    :func:`_components`' passes over them cost twice as much."""
    index = layout.index
    clamped = [index.points[point] for point, fixed in model.boundary.items() if all(fixed)]
    if not clamped:
        return False
    points = index.points
    joins = [(index.rigids[body.name], points[port]) for body in model.rigids for port in body.ports]
    joins += [(points[spring.ends[0]], points[spring.ends[1]])
              for spring, joint in zip(model.springs, _released_any(model.springs)) if not joint]
    joins += [(points[beam.ends[0]], points[beam.ends[1]]) for beam in model.beams]
    segments = components(len(points) + len(index.rigids), joins)
    return np.unique(segments[clamped]).size == segments.max() + 1


def _kinetic_directions(motions, M, weight):
    """The rigid motions' basis and kinetic energies (of :func:`_rigid_basis`): weighted
    (n_dof, r) orthonormal, basis (the same unweighted), kinetic (r,) and directions
    (r, r) the eigenpairs of its kinetic-energy matrix, massive (r,) bool which move mass."""
    weighted = la.orth(weight[:, None] * motions)
    basis = weighted / weight[:, None]
    kinetic, directions = la.eigh(basis.T @ (M @ basis))
    # against the model's own mass scale too: a joint can leave a motion of massless
    # points alone, whose kinetic energy is the rounding of the others' DOFs
    massive = kinetic > MASSLESS * max(np.abs(kinetic).max(), (M.diagonal() / weight ** 2).max())
    return weighted, basis, kinetic, directions, massive
