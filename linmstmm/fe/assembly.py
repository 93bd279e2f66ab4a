"""Assembly: global M, the natural factor G, D of K, and the constraint
elimination T of a meshed model (:class:`FEModel`, :func:`assemble`)."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from linmstmm.fe.elements import frame_elements
from linmstmm.fe.layout import (
    DofIndex,
    _layout,
    _Triplets,
    element_maps,
)
from linmstmm.fe.masses import _negligible_mass_removed
from linmstmm.fe.node_constraints import NodeConstraints, node_constraints
from linmstmm.fe.products import congruence, dense_product, small, transposed
from linmstmm.fe.rigid_motions import rigid_modes
from linmstmm.fe.sparse import as_scipy, scipy_csr, symmetric_part
from linmstmm.model import Model


class _BeamElements(NamedTuple):
    """The elements of every beam (``model.beams`` order) on a layout of n per beam.

    dofs : (b, n, 12) each element's full DOFs. to_local : (b, n, 12, 12) maps from
    them to its local ones. rows : (b, n, 6, 12) its six deformation rows on its full
    DOFs (m or rad). d : (b, 6) their stiffnesses. strain : (b, 6) which rows are
    strains (the others constraints). m : (b, 12, 12) local consistent masses, kg and
    kg m² (:func:`~linmstmm.fe.elements.frame_elements`).
    """

    dofs: np.ndarray
    to_local: np.ndarray
    rows: np.ndarray
    d: np.ndarray
    strain: np.ndarray
    m: np.ndarray


def _beam_elements(beams, maps, n) -> _BeamElements:
    """The :class:`_BeamElements` of ``beams`` (b :class:`~linmstmm.model.Beam`, ``n``
    elements each) whose elements' DOFs and maps to local ones are ``maps``
    ((b, n, 12), (b, n, 12, 12); :func:`~linmstmm.fe.layout.element_maps`)."""
    h = np.array([beam.length for beam in beams], float) / n
    rows, d, m, strain = frame_elements(beams, h)
    dofs, to_local = maps
    return _BeamElements(dofs, to_local, rows[:, None] @ to_local, d, strain, m)


def _add_beams(elements: _BeamElements, strains, mass):
    """Scatter the strains and masses of every beam element (beam after beam, element
    after element; their stiffnesses in that order are :func:`_beam_stiffnesses`)."""
    dofs, to_local, rows, d, strain, m = elements
    kept = np.broadcast_to(strain[:, None], rows.shape[:3])
    strains.add(strains.new_rows(np.count_nonzero(kept))[:, None],
                np.broadcast_to(dofs[:, :, None], kept.shape + (12,))[kept], rows[kept])
    mass.add(dofs[..., :, None], dofs[..., None, :], np.swapaxes(to_local, 2, 3) @ m[:, None] @ to_local)


def _beam_stiffnesses(elements: _BeamElements) -> np.ndarray:
    """The stiffnesses of the strain rows :func:`_add_beams` writes, in its order."""
    n = elements.dofs.shape[1]
    return np.repeat(elements.d, n, axis=0)[np.repeat(elements.strain, n, axis=0)]


def _add_beam_constraints(beams, maps, n, constraints):
    """Directions a beam declares rigid (``axial`` or ``torsion`` False) become constraints
    (beams and ``maps`` as for :func:`_beam_elements`; only those beams' elements are formed)."""
    held = [i for i, beam in enumerate(beams) if not (beam.axial and beam.torsion)]
    if not held:
        return
    elements = _beam_elements([beams[i] for i in held], (maps[0][held], maps[1][held]), n)
    rigid = np.broadcast_to(~elements.strain[:, None], elements.rows.shape[:3])
    constraints.add(constraints.new_rows(np.count_nonzero(rigid))[:, None],
                    np.broadcast_to(elements.dofs[:, :, None], rigid.shape + (12,))[rigid],
                    elements.rows[rigid])


@dataclass(frozen=True, eq=False)
class ConstrainedParts:
    """The nodes and exact constraints of a meshed model, with the parts that are
    not beams: what the FE assembly and the exact dynamic stiffness share.

    Attributes
    ----------
    layout : the node numbering, positions and frames.
    T : (n_full, n_dof) sparse elimination of every constraint (boundaries,
        rigid bodies' ports, infinite spring directions, beam directions declared
        rigid); the full vector is ``T @ q``. scipy CSR, or its arrays as a CSR
        :class:`~linmstmm.fe.sparse.Compressed` (:meth:`NodeConstraints.eliminated`).
    masters : (n_dof,) full DOFs kept as the reduced ones.
    n_full : 6 per node.
    spring_strains, spring_stiffness : the finite spring directions, as rows of
        the strain operator on the full DOFs (growing :class:`_Triplets`) and
        their stiffnesses (list of arrays, N/m or N m/rad).
    rigid_mass : the bodies' 6 × 6 mass blocks on the full DOFs (triplets).
    beam_maps : the beams' elements' full DOFs (b, n, 12) and maps to their local
        DOFs (b, n, 12, 12) on ``layout`` (:func:`~linmstmm.fe.layout.element_maps`).
    """

    layout: object
    T: sp.csr_matrix
    masters: np.ndarray
    n_full: int
    spring_strains: _Triplets
    spring_stiffness: list
    rigid_mass: _Triplets
    beam_maps: tuple


def constrained_parts(model: Model, elements_per_beam: int, nodes: NodeConstraints | None = None) -> ConstrainedParts:
    """Lay out ``model`` with ``elements_per_beam`` elements per beam, eliminate its
    constraints, and collect its springs and rigid masses (the beams' own
    stiffness and mass are left to the caller).

    nodes : the :class:`~linmstmm.fe.node_constraints.NodeConstraints` of ``model``
    (made here by default; :func:`~linmstmm.fe.node_constraints.kept_node_constraints`
    shares them among a model's meshes). Its rigid mass triplets are the parts'
    own: a caller that adds to them copies them first.
    """
    nodes = node_constraints(model) if nodes is None else nodes
    layout = _layout(model, elements_per_beam, nodes.layout)
    maps = element_maps(layout.beam_table, layout.beam_axes)
    beam_rows = _Triplets()
    _add_beam_constraints(model.beams, maps, elements_per_beam, beam_rows)
    n_full = 6 * layout.n_nodes
    T, masters = nodes.eliminated(beam_rows, n_full)
    return ConstrainedParts(layout, T, masters, n_full, nodes.spring_strains, nodes.spring_stiffness,
                            nodes.rigid_mass, maps)


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


@dataclass(frozen=True, eq=False)
class Assembly:
    """A meshed model's reduced matrices before its rigid-body modes are sought: what
    :func:`assemble` and the coarse predictions (:mod:`linmstmm.coarse_prediction`) share.

    Attributes
    ----------
    model : the model assembled, masses negligible against its own scale removed
        (:mod:`linmstmm.fe.masses`).
    parts : its :class:`ConstrainedParts` (layout, T, masters, n_full).
    M, K : (n_dof, n_dof) symmetric bit for bit: mass (kg, kg m²) and stiffness
        (N/m, N m/rad); dense numpy arrays where formed densely, scipy CSR otherwise
        (:func:`~linmstmm.fe.sparse.scipy_csr` makes either CSR).
    G, D : natural factor ``K = G.T @ diag(D) @ G``: G (n_strain, n_dof) scipy CSR
        (None where M and K were formed by a caller's ``forms``, which need no G),
        D (n_strain,).
    """

    model: Model
    parts: ConstrainedParts
    M: np.ndarray | sp.csr_matrix
    K: np.ndarray | sp.csr_matrix
    G: sp.csr_matrix | None
    D: np.ndarray


def assembled(model: Model, elements_per_beam: int, constraints_of=node_constraints, forms=None) -> Assembly:
    """The :class:`Assembly` of ``model`` with ``elements_per_beam`` (int >= 1) equal
    elements per beam; ``constraints_of`` (Model -> NodeConstraints) gives the
    constraints of its nodes (made anew by default, the kept ones of
    :func:`~linmstmm.fe.node_constraints.kept_node_constraints` for the coarse
    predictions), asked of ``model`` itself and given the masses that are left of it
    where some are negligible (:mod:`linmstmm.fe.masses`).

    M = Tᵀ M_full T and K = (Gᵀ D) G are formed densely where their dense
    intermediate (n_dof × n_full) is small (:func:`linmstmm.fe.products.small`), by
    scipy.sparse otherwise: the same matrices bit for bit either way. Where small,
    ``forms`` (T, elements, parts) -> (Tᵀ M_full T, Gᵀ D G) dense and symmetrised as
    :func:`_symmetric_of_dense` symmetrises, or None, with T
    (n_full, n_dof) scipy CSR, the beams' :class:`_BeamElements` and the
    :class:`ConstrainedParts`, may form them instead of :mod:`linmstmm.fe.products`:
    the same numbers required (the coarse predictions pass compiled ones), and G is
    then not formed.
    """
    nodes = constraints_of(model)       # the model's own (kept ones shared with its counter)
    light = _negligible_mass_removed(model, nodes.layout.positions)
    if light is not model:
        model, nodes = light, nodes.with_masses_of(light)
    parts = constrained_parts(model, elements_per_beam, nodes)
    T, n_full = parts.T, parts.n_full
    elements = _beam_elements(model.beams, parts.beam_maps, elements_per_beam)
    D = np.concatenate([_beam_stiffnesses(elements), *parts.spring_stiffness])   # beams' rows first, then the springs'
    formed = forms(T, elements, parts) if forms is not None and small(T.shape[1], n_full) else None
    if formed is not None:
        return Assembly(model, parts, *formed, None, D)
    parts = replace(parts, T=as_scipy(T))      # scipy's products below, and the FE model's T
    T = parts.T
    strains, mass = _Triplets(), parts.rigid_mass.copy()
    _add_beams(elements, strains, mass)
    strains.extend(parts.spring_strains)
    mass = mass.compressed(n_full, n_full)
    G = (strains.matrix(n_full) @ T).tocsr()
    weighted = transposed(G, D)                 # Gᵀ diag(D), G's own arrays
    if small(T.shape[1], n_full):
        M, K = (_symmetric_of_dense(product) for product in (congruence(T, mass), dense_product(weighted, G)))
    else:
        M = symmetric_part(T.T @ scipy_csr(mass) @ T)
        K = symmetric_part(sp.csc_matrix((weighted.data, weighted.indices, weighted.indptr), shape=weighted.shape) @ G)
    return Assembly(model, parts, M, K, G, D)


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
    assembly = assembled(model, n)
    layout, T, masters = assembly.parts.layout, assembly.parts.T, assembly.parts.masters
    M, K = scipy_csr(assembly.M), scipy_csr(assembly.K)
    modes, supports = rigid_modes(assembly.model, layout, masters, M)
    return FEModel(M=M, K=K, T=T, G=assembly.G, D=assembly.D, dof_index=layout.index,
                   n_dof=T.shape[1], n_full=assembly.parts.n_full, elements_per_beam=n,
                   rigid_modes=modes, supports=supports, frames=layout.frames,
                   massive=np.flatnonzero(M.diagonal()))


def _symmetric_of_dense(product: np.ndarray) -> np.ndarray:
    """(A + Aᵀ) / 2 of a dense square product A: the entries
    :func:`~linmstmm.fe.sparse.symmetric_part` makes of A's sparse form, (a + b) * 0.5."""
    return (product + product.T) * 0.5
