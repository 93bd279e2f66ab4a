"""Compiled making of a model's node constraints (:mod:`linmstmm.fe.node_constraints`),
for the Wittrick–Williams counter's build and the coarse pencil's, once the compiled
kernels are loaded (:func:`linmstmm.fe.port_following.compiled_nodes`):

* :func:`following_layout` — where each entry of T sits and where its number
  comes from, fixed by the structure (:func:`linmstmm.fe.port_following.port_following`
  took 55 µs of the launchers' first counter build in two dozen numpy calls on small
  arrays, 21 µs with this one loop over the full DOFs, the model's names read in
  Python included);
* :func:`following_entries` — T's stored entries from the nodes' positions
  (:meth:`linmstmm.fe.port_following.PortFollowing.T` in numpy);
* :func:`spring_entries` and :func:`rigid_mass_entries` — the springs' strain and
  constraint rows and the bodies' mass blocks as triplets
  (:func:`linmstmm.fe.node_constraints._add_springs_in_numpy`,
  :func:`~linmstmm.fe.node_constraints._add_rigid_masses_in_numpy`);
* :func:`element_entries` — the beams' elements' DOFs and maps to their local ones
  (:func:`linmstmm.fe.layout._element_maps_in_numpy`), for every mesh;
* :func:`held_nodes` — the springs', bodies' and elimination's of a model held at
  free points in one call (in a first solve each call of a kernel costs a few
  microseconds before it starts).

The model's records are read into flat arrays in Python (names to node numbers);
everything made of them here is one loop.

Integer for integer and bit for bit the arrays the numpy reference makes (each
lever-arm entry the same difference times the same sign, no fast-math);
tests/test_node_kernels.py compares both on the bundled and random models.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from linmstmm._compile_notice import announce_compiles

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)


@njit(cache=True)
def following_layout(n_full, port_nodes, centre_nodes, boundary_nodes, fixed, block_source, on_arm, arm_axes,
                     arm_signs):
    """The layout of T of a model held at free points, as
    :func:`linmstmm.fe.port_following.port_following` makes it.

    Parameters
    ----------
    n_full : int
        6 per point and mass centre.
    port_nodes, centre_nodes : (p,) int64
        Each port's node and its body's mass centre's, bodies and ports in model order.
    boundary_nodes : (f,) int64
        The nodes of the boundary's points.
    fixed : (f, 6) bool
        Their fixed components.
    block_source, on_arm : (6, 6) int64
        :data:`linmstmm.fe.port_following._BLOCK_SOURCE` and ``_ON_ARM``.
    arm_axes : (6,) int64. arm_signs : (6,) float64
        :data:`linmstmm.fe.port_following.ARM_AXES` and ``ARM_SIGNS``.

    Returns
    -------
    arm_ends, arm_starts : (6 p,) int64
        Where each port's and its mass centre's coordinates of its lever-arm entries sit
        in the flattened positions.
    arm_signs : (6 p,) float64
        The sign each lever-arm entry takes.
    rows, cols, source : (e,) int64
        :attr:`~linmstmm.fe.port_following.PortFollowing.rows`, ``cols`` and ``source``:
        DOF after DOF, a master's unit entry, a port's six entries in its block's order.
    masters : (n_dof,) int64
        The full DOFs kept, ascending.
    """
    p = port_nodes.size
    dropped = np.zeros(n_full, dtype=np.bool_)
    port_of = np.full(n_full, -1, dtype=np.int64)        # 6 i + component of port i's DOFs
    for i in range(p):
        for a in range(6):
            dropped[6 * port_nodes[i] + a] = True
            port_of[6 * port_nodes[i] + a] = 6 * i + a
    for b in range(boundary_nodes.size):
        for a in range(6):
            if fixed[b, a]:
                dropped[6 * boundary_nodes[b] + a] = True
    column = np.empty(n_full, dtype=np.int64)            # the reduced DOF of each kept one
    kept = 0
    for d in range(n_full):
        if not dropped[d]:
            kept += 1
        column[d] = kept - 1
    masters = np.empty(kept, dtype=np.int64)
    entries = kept + 36 * p
    rows, cols, source = (np.empty(entries, dtype=np.int64), np.empty(entries, dtype=np.int64),
                          np.empty(entries, dtype=np.int64))
    e = 0
    for d in range(n_full):
        if not dropped[d]:
            masters[column[d]] = d
            rows[e], cols[e], source[e] = d, column[d], 0
            e += 1
        if port_of[d] >= 0:
            i, a = port_of[d] // 6, port_of[d] % 6
            for c in range(6):  # the centre's six columns descending
                rows[e] = d
                cols[e] = column[6 * centre_nodes[i] + 5 - c]
                source[e] = block_source[a, c] + 6 * i * on_arm[a, c]
                e += 1
    arm_ends, arm_starts = np.empty(6 * p, dtype=np.int64), np.empty(6 * p, dtype=np.int64)
    signs = np.empty(6 * p)
    for i in range(p):
        for j in range(6):
            arm_ends[6 * i + j] = 3 * port_nodes[i] + arm_axes[j]
            arm_starts[6 * i + j] = 3 * centre_nodes[i] + arm_axes[j]
            signs[6 * i + j] = arm_signs[j]
    return arm_ends, arm_starts, signs, rows[:e], cols[:e], source[:e], masters


@njit(cache=True)
def following_entries(flat, arm_ends, arm_starts, arm_signs, rows, cols, source, n_full):
    """T's CSR arrays as :meth:`linmstmm.fe.port_following.PortFollowing.T` stores them
    (exact zeros left out).

    Parameters
    ----------
    flat : (3 n_nodes,) float64
        The nodes' positions (m), flattened.
    arm_ends, arm_starts, arm_signs, rows, cols, source :
        Those of the :class:`~linmstmm.fe.port_following.PortFollowing`.
    n_full : int
        T's rows.

    Returns
    -------
    indptr : (n_full + 1,) int64. indices : (nnz,) int64. data : (nnz,) float64, m or 1.
    """
    arms = (flat[arm_ends] - flat[arm_starts]) * arm_signs
    values = np.empty(source.size)
    stored = 0
    for e in range(source.size):
        s = source[e]
        values[e] = 1.0 if s == 0 else (0.0 if s == 1 else arms[s - 2])
        if values[e] != 0:
            stored += 1
    indptr = np.zeros(n_full + 1, dtype=np.int64)
    indices, data = np.empty(stored, dtype=np.int64), np.empty(stored)
    k = 0
    for e in range(source.size):
        if values[e] != 0:
            indices[k], data[k] = cols[e], values[e]
            indptr[rows[e] + 1] += 1
            k += 1
    for r in range(n_full):
        indptr[r + 1] += indptr[r]
    return indptr, indices, data


@njit(cache=True)
def spring_entries(ends, axes, stiffness, kept, direction_dofs):
    """The springs' kept directions as :func:`linmstmm.fe.node_constraints._add_springs`
    writes them: a finite one a strain row, an infinite one a constraint row, each
    the elongation (end b − end a along the spring's axis, m or rad) on the full DOFs
    (:func:`linmstmm.fe.layout.spring_rows`).

    Parameters
    ----------
    ends : (s, 2) int64
        Each spring's end nodes.
    axes : (s, 3, 3) float64
        Rows = each spring's local axes in the inertial frame.
    stiffness : (s, 6) float64
        N/m, N m/rad; ``inf`` where rigid.
    kept : (s, 6) bool
        False at the released directions.
    direction_dofs : (6, 3) int64
        :data:`linmstmm.fe.layout._DIRECTION_DOFS`: a direction's three DOFs at each end.

    Returns
    -------
    strains : (3,) tuple of (6 f,) arrays
        Rows (0 .. f − 1, the finite directions in the springs' order), columns (three
        at end a, then three at end b) and values (−axis, then +axis) of the strain rows.
    finite : (f,) float64
        Their stiffnesses.
    rigid : (3,) tuple of (6 r,) arrays
        The same of the infinite directions' constraint rows (0 .. r − 1).
    """
    n_finite, n_rigid = 0, 0
    for i in range(ends.shape[0]):
        for j in range(6):
            if kept[i, j]:
                if np.isinf(stiffness[i, j]):
                    n_rigid += 1
                else:
                    n_finite += 1
    finite = np.empty(n_finite)
    strain_rows, strain_cols, strain_values = (np.empty(6 * n_finite, dtype=np.int64),
                                               np.empty(6 * n_finite, dtype=np.int64), np.empty(6 * n_finite))
    rigid_rows, rigid_cols, rigid_values = (np.empty(6 * n_rigid, dtype=np.int64),
                                            np.empty(6 * n_rigid, dtype=np.int64), np.empty(6 * n_rigid))
    f, r = 0, 0
    for i in range(ends.shape[0]):
        for j in range(6):
            if not kept[i, j]:
                continue
            if np.isinf(stiffness[i, j]):
                rows, cols, values, row = rigid_rows, rigid_cols, rigid_values, r
                r += 1
            else:
                rows, cols, values, row = strain_rows, strain_cols, strain_values, f
                finite[f] = stiffness[i, j]
                f += 1
            for c in range(3):
                rows[6 * row + c], rows[6 * row + 3 + c] = row, row
                cols[6 * row + c] = 6 * ends[i, 0] + direction_dofs[j, c]
                cols[6 * row + 3 + c] = 6 * ends[i, 1] + direction_dofs[j, c]
                values[6 * row + c] = -axes[i, j % 3, c]
                values[6 * row + 3 + c] = axes[i, j % 3, c]
    return (strain_rows, strain_cols, strain_values), finite, (rigid_rows, rigid_cols, rigid_values)


@njit(cache=True)
def rigid_mass_entries(nodes, masses, inertias):
    """The bodies' 6 × 6 mass blocks on their mass centres' DOFs as
    :func:`linmstmm.fe.node_constraints._add_rigid_masses` writes them, row-major
    block after block, zeros included.

    Parameters
    ----------
    nodes : (r,) int64
        Each body's mass centre's node.
    masses : (r,) float64
        kg.
    inertias : (r, 3, 3) float64
        kg m², about the mass centre, inertial axes.

    Returns
    -------
    rows, cols : (36 r,) int64. values : (36 r,) float64.
    """
    r = nodes.size
    rows, cols, values = np.empty(36 * r, dtype=np.int64), np.empty(36 * r, dtype=np.int64), np.zeros(36 * r)
    for b in range(r):
        for i in range(6):
            for j in range(6):
                e = 36 * b + 6 * i + j
                rows[e], cols[e] = 6 * nodes[b] + i, 6 * nodes[b] + j
                if i == j and i < 3:
                    values[e] = masses[b]
                elif i >= 3 and j >= 3:
                    values[e] = inertias[b, i - 3, j - 3]
    return rows, cols, values


@njit(cache=True)
def element_entries(nodes, axes):
    """The elements' full DOFs and maps to their local DOFs as
    :func:`linmstmm.fe.layout.element_maps` makes them.

    Parameters
    ----------
    nodes : (b, n + 1) int64
        Each beam's nodes, end a to end b.
    axes : (b, 3, 3) float64
        Rows = each beam's local axes.

    Returns
    -------
    dofs : (b, n, 12) int64
        Each element's full DOFs, node 1 then node 2.
    to_local : (b, n, 12, 12) float64
        The identity, but for the beam's end nodes' DOFs (inertial), rotated by ``axes``.
    """
    b, n = nodes.shape[0], nodes.shape[1] - 1
    dofs = np.empty((b, n, 12), dtype=np.int64)
    to_local = np.zeros((b, n, 12, 12))
    for beam in range(b):
        for e in range(n):
            for a in range(6):
                dofs[beam, e, a], dofs[beam, e, 6 + a] = 6 * nodes[beam, e] + a, 6 * nodes[beam, e + 1] + a
            for a in range(12):
                to_local[beam, e, a, a] = 1.0
        for block in (0, 3):
            for i in range(3):
                for j in range(3):
                    to_local[beam, 0, block + i, block + j] = axes[beam, i, j]
                    to_local[beam, n - 1, 6 + block + i, 6 + block + j] = axes[beam, i, j]
    return dofs, to_local


@njit(cache=True)
def held_nodes(spring_ends, spring_axes, spring_stiffness, spring_kept, direction_dofs, rigid_nodes, rigid_masses,
               rigid_inertias, n_full, port_nodes, centre_nodes, boundary_nodes, fixed, block_source, on_arm,
               arm_axes, arm_signs, flat):
    """The node constraints of a model held at free points in one call: its springs'
    strain rows (:func:`spring_entries`), its bodies' mass entries
    (:func:`rigid_mass_entries`), the layout of its elimination
    (:func:`following_layout`) and T (:func:`following_entries`) of the nodes at
    ``flat``; the arguments theirs, in their order.

    Returns
    -------
    strains : (3,) tuple of (6 f,) arrays. stiffness : (f,) float64.
    mass : (3,) tuple of (36 r,) arrays.
    following : (7,) tuple of arrays, :func:`following_layout`'s.
    T : (3,) tuple of arrays, :func:`following_entries`'s.
    """
    strains, stiffness, _ = spring_entries(spring_ends, spring_axes, spring_stiffness, spring_kept, direction_dofs)
    mass = rigid_mass_entries(rigid_nodes, rigid_masses, rigid_inertias)
    following = following_layout(n_full, port_nodes, centre_nodes, boundary_nodes, fixed, block_source, on_arm,
                                 arm_axes, arm_signs)
    arm_ends, arm_starts, signs, rows, cols, source, _ = following
    return strains, stiffness, mass, following, following_entries(flat, arm_ends, arm_starts, signs, rows, cols,
                                                                  source, n_full)
