"""The parts of a meshed model that lie on its nodes alone — springs, boundaries,
rigid bodies' ports and masses — and the elimination of their constraints, made
once per model and extended to any mesh.

A mesh numbers the model's points and mass centres first and every interior
beam node after them (:class:`~linmstmm.fe.layout.DofIndex`), and no spring,
boundary or port touches an interior node. So the port map T0 of a mesh is the
nodes' own with an identity row and column for each interior DOF, and where no
beam declares a direction rigid (the only constraints on interior nodes) the
elimination T of a mesh is the nodes' own T with the same identity block: the
same arrays, entry for entry, as eliminating that mesh's constraints from the
start. The Wittrick–Williams counter (one element per beam) and the coarse
predicting mesh (two or more) of one model object share one such elimination
(:func:`kept_node_constraints`); the FE route makes its own.
"""
from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from linmstmm.fe.constraints import _eliminate, reduced_constraints
from linmstmm.fe.layout import _DIRECTION_DOFS, _layout, _Triplets, compiled_nodes, spring_rows
from linmstmm.fe.port_following import (
    FOLLOWING_CONSTANTS,
    PortFollowing,
    followed,
    following_nodes,
    kept_port_following,
    port_kinematics,
)
from linmstmm.fe.sparse import Compressed, scipy_csr
from linmstmm.model import Model

#: Model objects whose node constraints are kept (:func:`kept_node_constraints`),
#: least recently used dropped first.
CONSTRAINTS_KEPT = 16


@dataclass(frozen=True, eq=False)
class NodeConstraints:
    """A model's springs, boundaries, ports and rigid masses on its points and mass
    centres (6 DOFs each, ``n_full`` in all), before any beam is meshed.

    Attributes
    ----------
    layout : linmstmm.fe.layout._Layout
        The points and mass centres (the layout of one element per beam).
    n_full : int
        6 per point and mass centre.
    port_map : Compressed or None
        T0 (n_full, q0) CSR: each port moves with the first body that owns it.
    kept : numpy.ndarray, shape (q0,), or None
        The full DOFs T0 keeps, ascending.
    rows : Compressed or None
        (r, n_full) CSR constraint rows: infinite spring directions, fixed
        boundary components, ports joining further bodies, in that order.
        These three are None where the model is :func:`held_at_free_points`: its
        elimination is then made directly (``following``), and no mesh eliminates anew.
    spring_strains : linmstmm.fe.layout._Triplets
        The finite spring directions as strain rows (m or rad) on the full DOFs.
    spring_stiffness : list of numpy.ndarray
        Their stiffnesses, N/m or N m/rad.
    rigid_mass : linmstmm.fe.layout._Triplets
        The bodies' 6 × 6 mass blocks (kg, kg m²) on their mass centres' DOFs.
    elimination : tuple or None
        (T (n_full, n_dof) CSR, masters (n_dof,) full DOFs) of ``rows`` where no
        beam declares a direction rigid, else None. T is scipy CSR, or its arrays
        as :class:`~linmstmm.fe.sparse.Compressed` where made by ``following``.
    following : linmstmm.fe.port_following.PortFollowing or None
        Where the model is :func:`held_at_free_points`, the layout of its elimination
        (fixed by its structure), which made T; else None.
    """

    layout: object
    n_full: int
    port_map: Compressed
    kept: np.ndarray
    rows: Compressed
    spring_strains: _Triplets
    spring_stiffness: list
    rigid_mass: _Triplets
    elimination: tuple | None
    following: PortFollowing | None

    def with_masses_of(self, model: Model) -> NodeConstraints:
        """These constraints with the rigid masses of ``model``: the same model but for
        its masses (:func:`~linmstmm.fe.masses._negligible_mass_removed`), on which
        nothing else here depends.

        Parameters
        ----------
        model : Model
            The model these were made of, its masses changed.

        Returns
        -------
        NodeConstraints
        """
        mass = _Triplets(repeats=True)
        _add_rigid_masses(model, self.layout, mass)
        return dataclasses.replace(self, rigid_mass=mass)

    def eliminated(self, beam_rows: _Triplets, n_full: int) -> tuple[sp.csr_matrix, np.ndarray]:
        """The elimination of a mesh's constraints: the same arrays as eliminating them anew.

        Parameters
        ----------
        beam_rows : linmstmm.fe.layout._Triplets
            The constraint rows the mesh's beams add (directions a beam declares
            rigid), on its full DOFs; taken before the nodes' rows.
        n_full : int
            The mesh's full DOFs: these nodes' ``n_full``, then 6 per interior beam node.

        Returns
        -------
        T : scipy.sparse.csr_matrix or Compressed, shape (n_full, n_dof)
            The full vector is ``T @ q``. Where the nodes' elimination is extended by
            the interior nodes' identity or made by ``following``, the arrays as
            :class:`Compressed` CSR (their scipy matrix: :func:`~linmstmm.fe.sparse.as_scipy`).
        masters : numpy.ndarray, shape (n_dof,)
            The full DOFs kept as the reduced ones, ascending.
        """
        interior = np.arange(self.n_full, n_full)
        if not beam_rows.n_rows and self.elimination is not None:
            T, masters = self.elimination
            if not interior.size:       # the nodes themselves (one element per beam)
                return T, masters
            T = Compressed("csr", T.indptr, T.indices, T.data, T.shape)
            return _with_identity(T, len(interior)), np.concatenate([masters, interior])
        t0 = scipy_csr(_with_identity(self.port_map, len(interior)))
        t1, masters = _eliminate(reduced_constraints(_stacked(beam_rows.compressed(n_full), self.rows), t0))
        return (t0 @ scipy_csr(t1)).tocsr(), np.concatenate([self.kept, interior])[masters]


def node_constraints(model: Model) -> NodeConstraints:
    """The :class:`NodeConstraints` of ``model``, made anew (but for the layout of a
    held model's elimination, kept by its structure:
    :func:`~linmstmm.fe.port_following.kept_port_following`).

    Parameters
    ----------
    model : Model
        The model; its rigid masses are taken as they are.

    Returns
    -------
    NodeConstraints
    """
    layout = _layout(model, 1)              # the points and mass centres only
    n_full = 6 * layout.n_nodes
    held = held_at_free_points(model)
    if held and compiled_nodes():
        return _held_node_constraints(model, layout)
    strains, mass, constraints = _Triplets(), _Triplets(repeats=True), _Triplets()
    stiffness = []
    _add_springs(model, layout, strains, stiffness, constraints)
    _add_rigid_masses(model, layout, mass)
    if held:
        following = kept_port_following(model, layout)
        return NodeConstraints(layout, n_full, None, None, None, strains, stiffness, mass,
                               (following.T(layout.positions), following.masters), following)
    _add_boundaries(model, layout, constraints)
    t0, kept = _port_map(model, layout, constraints)
    rows = constraints.compressed(n_full)
    elimination = None
    if all(beam.axial and beam.torsion for beam in model.beams):
        t0_csr = scipy_csr(t0)
        t1, masters = _eliminate(reduced_constraints(rows, t0_csr))
        elimination = ((t0_csr @ scipy_csr(t1)).tocsr(), kept[masters])
    return NodeConstraints(layout, n_full, t0, kept, rows, strains, stiffness, mass, elimination, None)


def _held_node_constraints(model: Model, layout) -> NodeConstraints:
    """:func:`node_constraints` of a model :func:`held_at_free_points`, made in one call of
    :func:`linmstmm._node_kernels.held_nodes` (the same arrays as made step by step), its
    elimination's layout kept by its structure as :func:`kept_port_following` keeps it."""
    from linmstmm._node_kernels import held_nodes

    n_full = 6 * layout.n_nodes
    strain_rows, stiffness, mass_entries, arrays, entries = held_nodes(
        *_spring_arrays(model, layout), *_rigid_arrays(model, layout), n_full, *following_nodes(model, layout),
        *FOLLOWING_CONSTANTS, layout.positions.ravel())
    strains, mass = _Triplets(), _Triplets(repeats=True)
    strains.add(*strain_rows)
    strains.new_rows(len(stiffness))
    mass.add(*mass_entries)
    following = kept_port_following(model, layout, followed(n_full, arrays))
    return NodeConstraints(layout, n_full, None, None, None, strains, [stiffness], mass,
                           (following.compressed(*entries), following.masters), following)


def held_at_free_points(model: Model) -> bool:
    """Whether every constraint of ``model`` is a fixed boundary component of a point that
    no rigid body owns: no point owned by two bodies, no ``inf`` spring direction, no
    beam rigid axially or in torsion. Its structure decides it.

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    bool
    """
    ports = [port for body in model.rigids for port in body.ports]
    owned = set(ports)
    return (len(owned) == len(ports) and owned.isdisjoint(model.boundary)
            and not np.isinf([spring.k for spring in model.springs]).any()
            and all(beam.axial and beam.torsion for beam in model.beams))


#: :func:`node_constraints` kept per model object (a Model cannot change): made on the
#: first call, shared by the counter's and the coarse predictions' meshes of the model.
kept_node_constraints = functools.lru_cache(maxsize=CONSTRAINTS_KEPT)(node_constraints)


def _with_identity(matrix, extra: int):
    """``matrix`` (CSR, scipy or :class:`Compressed`) with ``extra`` rows and columns of
    the identity appended, its own entries stored as they are; of its kind."""
    n_rows, n_cols = matrix.shape
    indptr = np.concatenate([matrix.indptr, matrix.indptr[-1] + np.arange(1, extra + 1, dtype=matrix.indptr.dtype)])
    indices = np.concatenate([matrix.indices, np.arange(n_cols, n_cols + extra, dtype=matrix.indices.dtype)])
    data = np.concatenate([matrix.data, np.ones(extra)])
    shape = (n_rows + extra, n_cols + extra)
    if isinstance(matrix, Compressed):
        return Compressed("csr", indptr, indices, data, shape)
    return sp.csr_matrix((data, indices, indptr), shape=shape)


def _stacked(top: Compressed, bottom: Compressed) -> Compressed:
    """The CSR rows of ``top`` above those of ``bottom`` (no wider than ``top``), of
    ``top``'s width."""
    indptr = np.concatenate([top.indptr, top.indptr[-1] + bottom.indptr[1:]])
    return Compressed("csr", indptr, np.concatenate([top.indices, bottom.indices]),
                      np.concatenate([top.data, bottom.data]), (top.shape[0] + bottom.shape[0], top.shape[1]))


def _add_springs(model, layout, strains, stiffness, constraints):
    """Finite spring directions become strains, ``inf`` ones constraints, released ones nothing
    (each kind written as one block of rows, in the springs' order): by
    :func:`linmstmm._node_kernels.spring_entries` where :func:`compiled_nodes`, the same
    entries as :func:`_add_springs_in_numpy`."""
    if not compiled_nodes():
        _add_springs_in_numpy(model, layout, strains, stiffness, constraints)
        return
    from linmstmm._node_kernels import spring_entries

    (rows, cols, values), k, rigid = spring_entries(*_spring_arrays(model, layout))
    if len(rigid[0]):
        constraints.add(rigid[0] + constraints.new_rows(len(rigid[0]) // 6)[0], *rigid[1:])
    strains.add(rows + strains.n_rows, cols, values)
    strains.new_rows(len(k))
    stiffness.append(k)


def _spring_arrays(model, layout) -> tuple:
    """(ends (s, 2) nodes, axes (s, 3, 3), k (s, 6) N/m or N m/rad, kept (s, 6) bool, the
    directions' DOFs (6, 3)): the springs of ``model`` on ``layout`` as
    :func:`linmstmm._node_kernels.spring_entries` takes them."""
    springs, points = model.springs, layout.index.points
    ends = np.array([(points[spring.ends[0]], points[spring.ends[1]]) for spring in springs], int).reshape(-1, 2)
    axes = np.array([spring.axes for spring in springs], float).reshape(-1, 3, 3)
    k = np.array([spring.k for spring in springs], float).reshape(-1, 6)
    kept = np.ones(k.shape, bool)
    for i, spring in enumerate(springs):
        if spring.release is not None:
            kept[i] = ~np.asarray(spring.release, bool)
    return ends, axes, k, kept, _DIRECTIONS


#: :data:`linmstmm.fe.layout._DIRECTION_DOFS` as (6, 3): each direction's three DOFs at an end.
_DIRECTIONS = _DIRECTION_DOFS.reshape(6, 3)


def _add_springs_in_numpy(model, layout, strains, stiffness, constraints):
    """:func:`_add_springs` in numpy: the readable reference of
    :func:`linmstmm._node_kernels.spring_entries`."""
    owners, components, cols, values = spring_rows(model.springs, layout.index, kept_only=True)
    k = np.array([spring.k for spring in model.springs], float).reshape(-1, 6)
    k = k.ravel() if len(owners) == k.size else k[owners, components]   # every direction kept: all, in order
    rigid = np.isinf(k)
    if rigid.any():  # else every direction a strain, taken as it is
        constraints.add(constraints.new_rows(np.count_nonzero(rigid))[:, None], cols[rigid], values[rigid])
        k, cols, values = k[~rigid], cols[~rigid], values[~rigid]
    strains.add(strains.new_rows(len(k))[:, None], cols, values)
    stiffness.append(k)


def _add_rigid_masses(model, layout, mass):
    """Each body's mass and inertia on the DOFs of its mass centre: by
    :func:`linmstmm._node_kernels.rigid_mass_entries` where :func:`compiled_nodes`, the
    same entries as :func:`_add_rigid_masses_in_numpy`."""
    if not compiled_nodes():
        _add_rigid_masses_in_numpy(model, layout, mass)
        return
    from linmstmm._node_kernels import rigid_mass_entries

    mass.add(*rigid_mass_entries(*_rigid_arrays(model, layout)))


def _rigid_arrays(model, layout) -> tuple:
    """(nodes (r,), masses (r,) kg, inertias (r, 3, 3) kg m²): the bodies' mass centres on
    ``layout`` and their masses, as :func:`linmstmm._node_kernels.rigid_mass_entries` takes them."""
    rigids = layout.index.rigids
    nodes = np.array([rigids[body.name] for body in model.rigids], int)
    inertias = np.array([body.inertia for body in model.rigids], float).reshape(-1, 3, 3)
    return nodes, np.array([body.mass for body in model.rigids], float), inertias


def _add_rigid_masses_in_numpy(model, layout, mass):
    """:func:`_add_rigid_masses` in numpy: the readable reference of
    :func:`linmstmm._node_kernels.rigid_mass_entries`."""
    dofs = 6 * np.array([layout.index.rigids[body.name] for body in model.rigids], int)[:, None] + np.arange(6)
    blocks = np.zeros((len(dofs), 36))                                    # each body's 6 × 6 block, row-major
    blocks[:, :15:7] = np.array([body.mass for body in model.rigids], float)[:, None]
    blocks[:, _INERTIA_PLACES] = np.array([body.inertia for body in model.rigids], float).reshape(-1, 9)
    mass.add(np.repeat(dofs, 6, axis=1).ravel(), np.tile(dofs, 6).ravel(), blocks.ravel())


#: Where a body's inertia tensor (3 × 3, row-major) sits in its 6 × 6 mass block, flattened.
_INERTIA_PLACES = (6 * np.arange(3, 6)[:, None] + np.arange(3, 6)).ravel()


def _add_boundaries(model, layout, constraints):
    """Every fixed component of a point becomes a constraint row of its own."""
    dofs = [layout.index.point(point)[np.asarray(fixed, bool)] for point, fixed in model.boundary.items()]
    dofs = np.concatenate(dofs) if dofs else np.zeros(0, int)
    constraints.add(constraints.new_rows(len(dofs)), dofs, 1.0)


def _port_map(model, layout, constraints):
    """(T0 (full x q0) CSR rows, (q0,) the full DOFs it keeps): each port moves with the first body that owns it.

    A point that is a port of several bodies gets six constraint rows per
    further body (the bodies are rigidly joined there).
    """
    n_full = 6 * layout.n_nodes
    bodies = [(body, port) for body in model.rigids for port in body.ports]
    owned = {}
    first = np.array([owned.setdefault(port, i) == i for i, (_, port) in enumerate(bodies)], bool)
    port_nodes = np.array([layout.index.points[port] for _, port in bodies], int)
    centre_nodes = np.array([layout.index.rigids[body.name] for body, _ in bodies], int)
    ports, centres = (6 * nodes.reshape(-1, 1) + np.arange(6) for nodes in (port_nodes, centre_nodes))
    kinematics = port_kinematics(layout.positions[port_nodes], layout.positions[centre_nodes])
    if not first.all():
        joined = constraints.new_rows(6 * np.count_nonzero(~first)).reshape(-1, 6, 1)
        constraints.add(joined, ports[~first][:, None, :], np.eye(6))
        constraints.add(joined, centres[~first][:, None, :], -kinematics[~first])
    slaved = np.zeros(n_full, bool)
    slaved[ports[first]] = True
    kept = np.flatnonzero(~slaved)
    column_of = np.full(n_full, -1)
    column_of[kept] = np.arange(len(kept))
    # rows in order: a slaved port DOF holds its body's six centre DOFs (columns
    # ascending, zeros kept), every other DOF itself
    indptr = np.zeros(n_full + 1, int)
    np.cumsum(np.where(slaved, 6, 1), out=indptr[1:])
    indices, data = np.empty(indptr[-1], int), np.empty(indptr[-1])
    indices[indptr[kept]], data[indptr[kept]] = np.arange(len(kept)), 1.0
    held = indptr[ports[first]][..., None] + np.arange(6)                   # (p, 6, 6)
    indices[held], data[held] = column_of[centres[first]][:, None, :], kinematics[first]
    return Compressed("csr", indptr, indices, data, (n_full, len(kept))), kept
