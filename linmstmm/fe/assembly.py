"""Assembly: global M, the natural factor G, D of K, and the constraint
elimination T of a meshed model (:class:`FEModel`, :func:`assemble`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from linmstmm.fe.constraints import _drop_debris, _eliminate
from linmstmm.fe.elements import beam_element
from linmstmm.fe.layout import DofIndex, _layout, _spring_directions, _Triplets
from linmstmm.fe.masses import _negligible_mass_removed
from linmstmm.fe.rigid_motions import _rigid_basis, _rigid_motions
from linmstmm.model import Model


def beam_element_dofs(layout, beam, n):
    """(n, 12) full DOFs of the elements of ``beam`` and (n, 12, 12) their maps from
    those DOFs to the element's local ones (end nodes are inertial, interior ones local)."""
    nodes = layout.index.beam_nodes[beam.name]
    to_local = np.tile(np.eye(12), (n, 1, 1))
    axes = np.asarray(beam.axes, float)
    for block in (0, 3):
        to_local[0, block:block + 3, block:block + 3] = axes
        to_local[-1, 6 + block:9 + block, 6 + block:9 + block] = axes
    dofs = np.concatenate([6 * nodes[:-1, None] + np.arange(6),
                           6 * nodes[1:, None] + np.arange(6)], axis=1)
    return dofs, to_local


def _add_beams(model, layout, n, strains, stiffness, mass):
    """Scatter every beam element (vectorised over the elements of a beam)."""
    for beam in model.beams:
        g, d, m, _ = beam_element(beam, beam.length / n)
        dofs, to_local = beam_element_dofs(layout, beam, n)
        g_elements = g @ to_local                              # (n, s, 12)
        rows = strains.new_rows(n * len(d)).reshape(n, len(d))
        strains.add(rows[:, :, None], dofs[:, None, :], g_elements)
        stiffness.append(np.tile(d, n))
        m_elements = np.swapaxes(to_local, 1, 2) @ m @ to_local
        mass.add(dofs[:, :, None], dofs[:, None, :], m_elements)


def _add_beam_constraints(model, layout, n, constraints):
    """Directions a beam declares rigid (``axial`` or ``torsion`` False) become constraints."""
    for beam in model.beams:
        c = beam_element(beam, beam.length / n)[3]
        if len(c):
            dofs, to_local = beam_element_dofs(layout, beam, n)
            rows = constraints.new_rows(n * len(c)).reshape(n, len(c))
            constraints.add(rows[:, :, None], dofs[:, None, :], c @ to_local)


def _add_springs(model, layout, strains, stiffness, constraints):
    """Finite spring directions become strains, ``inf`` ones constraints, released ones nothing
    (each kind written as one block of rows, in the springs' order)."""
    finite, rigid = ([], [], []), ([], [])
    for spring in model.springs:
        for component, cols, values in _spring_directions(spring, layout.index, kept_only=True):
            k = float(spring.k[component])
            if np.isinf(k):
                rigid[0].append(cols)
                rigid[1].append(values)
            else:
                finite[0].append(cols)
                finite[1].append(values)
                finite[2].append(k)
    if finite[0]:
        strains.add(strains.new_rows(len(finite[0]))[:, None], np.array(finite[0]), np.array(finite[1]))
        stiffness.append(np.array(finite[2]))
    if rigid[0]:
        constraints.add(constraints.new_rows(len(rigid[0]))[:, None], np.array(rigid[0]), np.array(rigid[1]))


def _add_rigid_masses(model, layout, mass):
    for body in model.rigids:
        dofs = layout.index.rigid(body.name)
        block = np.zeros((6, 6))
        block[:3, :3] = body.mass * np.eye(3)
        block[3:, 3:] = body.inertia
        mass.add(dofs[:, None], dofs[None, :], block)


def _add_boundaries(model, layout, constraints):
    for point, fixed in model.boundary.items():
        dofs = layout.index.point(point)[np.asarray(fixed, bool)]
        constraints.add(constraints.new_rows(len(dofs)), dofs, 1.0)


def _port_kinematics(port, centre) -> np.ndarray:
    """(6, 6) map body-centre DOFs -> port DOFs: u_p = u_c + θ × (p − c), θ_p = θ."""
    r = np.asarray(port, float) - np.asarray(centre, float)
    block = np.eye(6)
    block[:3, 3:] = -np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])
    return block


def _port_map(model, layout, constraints):
    """Sparse T0 (full x q0): each port moves with the first body that owns it.

    A point that is a port of several bodies gets six constraint rows per
    further body (the bodies are rigidly joined there).
    """
    n_full = 6 * layout.n_nodes
    slaved = np.zeros(n_full, bool)
    rows, cols, values = [], [], []
    owner = {}
    for body in model.rigids:
        centre = layout.index.rigid(body.name)
        for port in body.ports:
            kinematics = _port_kinematics(model.points[port], body.com)
            dofs = layout.index.point(port)
            if port in owner:
                constraint_rows = constraints.new_rows(6)
                constraints.add(constraint_rows[:, None], dofs[None, :], np.eye(6))
                constraints.add(constraint_rows[:, None], centre[None, :], -kinematics)
                continue
            owner[port] = body.name
            slaved[dofs] = True
            rows.append(np.repeat(dofs, 6))
            cols.append(np.tile(centre, 6))
            values.append(kinematics.ravel())
    kept = np.flatnonzero(~slaved)
    column_of = np.full(n_full, -1)
    column_of[kept] = np.arange(len(kept))
    rows.append(kept)
    cols.append(kept)
    values.append(np.ones(len(kept)))
    rows, cols, values = map(np.concatenate, (rows, cols, values))
    return sp.csr_matrix((values, (rows, column_of[cols])), shape=(n_full, len(kept))), kept


@dataclass(frozen=True, eq=False)
class ConstrainedParts:
    """The nodes and exact constraints of a meshed model, with the parts that are
    not beams: what the FE assembly and the exact dynamic stiffness share.

    Attributes
    ----------
    layout : the node numbering, positions and frames.
    T : (n_full, n_dof) sparse elimination of every constraint (boundaries,
        rigid bodies' ports, infinite spring directions, beam directions declared
        rigid); the full vector is ``T @ q``.
    masters : (n_dof,) full DOFs kept as the reduced ones.
    n_full : 6 per node.
    spring_strains, spring_stiffness : the finite spring directions, as rows of
        the strain operator on the full DOFs (growing :class:`_Triplets`) and
        their stiffnesses (list of arrays, N/m or N m/rad).
    rigid_mass : the bodies' 6 × 6 mass blocks on the full DOFs (triplets).
    """

    layout: object
    T: sp.csr_matrix
    masters: np.ndarray
    n_full: int
    spring_strains: _Triplets
    spring_stiffness: list
    rigid_mass: _Triplets


def constrained_parts(model: Model, elements_per_beam: int) -> ConstrainedParts:
    """Lay out ``model`` with ``elements_per_beam`` elements per beam, eliminate its
    constraints, and collect its springs and rigid masses (the beams' own
    stiffness and mass are left to the caller)."""
    layout = _layout(model, elements_per_beam)
    n_full = 6 * layout.n_nodes
    strains, mass, constraints = _Triplets(), _Triplets(), _Triplets()
    stiffness = []
    _add_beam_constraints(model, layout, elements_per_beam, constraints)
    _add_springs(model, layout, strains, stiffness, constraints)
    _add_rigid_masses(model, layout, mass)
    _add_boundaries(model, layout, constraints)
    t0, q0_dofs = _port_map(model, layout, constraints)
    reduced_constraints = _drop_debris(constraints.matrix(n_full) @ t0)
    t1, masters = _eliminate(reduced_constraints)
    return ConstrainedParts(layout, (t0 @ t1).tocsr(), q0_dofs[masters], n_full, strains, stiffness, mass)


@dataclass(frozen=True, eq=False)
class FEModel:
    """A meshed, constrained model: ``M q̈ + K q = f`` in reduced DOFs ``q``.

    Attributes
    ----------
    M, K : (n_dof, n_dof) sparse symmetric mass (kg, kg m²) and stiffness
        (N/m, N m/rad). M is singular when the model has massless DOFs; K is
        singular for each rigid-body mode.
    T : (n_full, n_dof) sparse; the full vector is ``T @ q``. The reduced
        DOFs are a subset of the full ones (T has identity rows there), so a
        force ``f_full`` enters as ``T.T @ f_full``.
    G, D : natural factor ``K = G.T @ diag(D) @ G``; G (n_strain, n_dof) maps
        DOFs to element strains, D (n_strain,) their stiffnesses.
    dof_index : :class:`DofIndex`, where points, mass centres and beam nodes
        sit in the full vector.
    n_dof, n_full : sizes of the reduced and full vectors.
    elements_per_beam : mesh used for every beam.
    rigid_modes : (n_dof, r) M-orthonormal zero-frequency modes.
    supports : (r_all,) reduced DOFs whose fixing removes every rigid motion
        (statically determinate temporary supports, used by the solver).
    frames : (n_nodes, 3, 3) rows = the axes of each node's DOFs (identity
        except at interior beam nodes).
    massive : (n_massive,) reduced DOFs that carry mass, ascending. The others
        have exactly zero rows and columns in M (masses negligible against the
        model's own scale are removed first) and are condensed out statically
        by the eigensolver.
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    T: sp.csr_matrix
    G: sp.csr_matrix
    D: np.ndarray
    dof_index: DofIndex
    n_dof: int
    n_full: int
    elements_per_beam: int
    rigid_modes: np.ndarray
    supports: np.ndarray
    frames: np.ndarray
    massive: np.ndarray

    def beam_motion(self, name: str, q_full: np.ndarray) -> np.ndarray:
        """(n+1, 6) inertial displacements and rotations along beam ``name``.

        q_full : (n_full,) full vector, e.g. ``T @ q``.
        """
        nodes = self.dof_index.beam_nodes[name]
        values = np.asarray(q_full)[self.dof_index.beam(name)].reshape(-1, 2, 3)
        to_inertial = np.swapaxes(self.frames[nodes], 1, 2)[:, None]
        return (to_inertial @ values[..., None])[..., 0].reshape(-1, 6)


def assemble(model: Model, elements_per_beam: int = 8) -> FEModel:
    """Global mass and stiffness of ``model`` with all constraints eliminated.

    Parameters
    ----------
    model : the model records.
    elements_per_beam : int >= 1, equal elements per beam.
    """
    n = int(elements_per_beam)
    if n < 1:
        raise ValueError(f"elements_per_beam must be >= 1, got {elements_per_beam}")
    model = _negligible_mass_removed(model)
    parts = constrained_parts(model, n)
    layout, T, masters, n_full = parts.layout, parts.T, parts.masters, parts.n_full
    strains, mass, stiffness = _Triplets(), parts.rigid_mass, []
    _add_beams(model, layout, n, strains, stiffness, mass)
    strains.extend(parts.spring_strains)       # beams' rows first, then the springs'
    stiffness += parts.spring_stiffness

    G = (strains.matrix(n_full) @ T).tocsr()
    D = np.concatenate(stiffness) if stiffness else np.zeros(0)
    M = _symmetric(T.T @ mass.matrix(n_full, n_full) @ T)
    K = _symmetric(G.T @ sp.diags(D) @ G)
    motions, weight = _rigid_motions(model, layout)
    rigid_modes, supports = _rigid_basis(motions[masters], M, weight[masters])
    return FEModel(M=M, K=K, T=T, G=G, D=D, dof_index=layout.index,
                   n_dof=T.shape[1], n_full=n_full, elements_per_beam=n,
                   rigid_modes=rigid_modes, supports=supports, frames=layout.frames,
                   massive=np.flatnonzero(M.diagonal()))


def _symmetric(matrix) -> sp.csr_matrix:
    return ((matrix + matrix.T) * 0.5).tocsr()
