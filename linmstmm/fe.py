"""The ordinary finite-element route: global M and K, generalized eigenproblem.

This module is the independent cross-check of the transfer-matrix code and its
speed baseline. It shares nothing with it but the model records.

Discretisation
--------------
Every node carries six DOFs ``(ux, uy, uz, θx, θy, θz)``. Nodes are the model
points, the mass centres of the rigid bodies and the interior nodes of each
beam, which is cut into ``n`` equal 3-D frame elements: cubic Hermite bending
in both principal planes with consistent mass ρA (no rotary inertia), linear
axial (EA, ρA) and torsion (GJ, ρ·Ip) with consistent mass. Springs are
massless and of zero length; rigid bodies carry m and J_c at their mass centre.
A spring's released directions (a joint) have no stiffness at all: neither
a strain nor a constraint joins its two end nodes there.

Constraints are exact, never penalties: ports of rigid bodies, ``inf`` spring
directions, ``axial=False`` / ``torsion=False`` and boundary conditions are
linear homogeneous equations on the DOFs, eliminated by a sparse master–slave
transformation ``q = T q_r`` whose masters are a subset of the full DOFs.

Accuracy: the natural-factor (mixed) formulation
------------------------------------------------
Assembled stiffness matrices of fine meshes lose the low modes: rounding each
entry of K is a perturbation of size ε·|K| that acts like tiny springs to
ground, so a low eigenvalue λ_1 carries an error of order ε·λ_max, relative
error ~ ε·n⁴ for a beam cut into n elements (1e-8 at n = 128, 1e-4 at
n = 1000 with shift-invert on (K, M)). Here K is never factorised. It is kept
as its natural factor ``K = Gᵀ diag(D) G``: G maps DOFs to element strains
(spring elongations, rod stretch and twist, and for each bending plane the
relative rotation θ₂−θ₁ and the chord-rotation defect (θ₁+θ₂)/2 − (w₂−w₁)/h),
D holds the element stiffnesses. Then

* the flexibility solve ``K y = f`` goes through the mixed (force–displacement)
  system ``[[-D⁻¹, G], [Gᵀ, 0]] [s; y] = [0; f]``, whose pivots are
  element-level quantities, so equilibrium and compatibility are solved
  without the ε·λ_max cancellation;
* every Rayleigh quotient is an energy computed from strains,
  ``λ = |D^½ G x|² / xᵀ M x``, never from ``xᵀ K x``.

Lanczos (ARPACK) on the operator ``K⁺M`` supplies approximate modes; a few
sweeps of subspace (inverse) iteration with Rayleigh–Ritz in the natural
factor then give eigenvalues whose rounding error stays near 1e-15 relative
even at thousands of elements per beam.

Rigid-body modes and massless DOFs
----------------------------------
Zero-frequency modes are counted structurally, not by a threshold on computed
eigenvalues: every segment of the model (nodes joined by elements other than
joints) has the six rigid motions, of which those compatible with the
boundary conditions and with the directions each joint keeps, and carrying
mass (a positive kinetic energy, 1e-13 relative to the largest), are the
rigid-body and mechanism modes. They are deflated exactly: K is made invertible by temporary
statically determinate supports on as many DOFs as there are rigid motions,
and the solve is projected M-orthogonally off the rigid-body modes.

Massless DOFs (a point between two springs, a spring's free far end, a
massless body or beam) are condensed out statically, which is exact since
their inertia is exactly zero: masses below 1e-13 of the model's own scale
(its total mass, and for inertias that times its extent squared) are removed
first (:func:`_negligible_mass_removed`), so such DOFs have zero rows in M.
The flexibility ``K⁺`` applied to inertial loads moves them statically, and
the eigenproblem is posed on the directions that carry mass only: the model
has exactly rank M less its rigid-body modes elastic modes, and a massless
direction (infinite frequency) is never taken for one. A model whose mass
all sits in rigid-body motions has no elastic mode. A rigid motion without
mass (a point mass without rotary inertia and with nothing holding its
rotation) has neither mass nor stiffness; it is not a mode and is neither
counted nor reported.

Mesh refinement
---------------
Consistent-mass eigenvalues decrease monotonically under mesh doubling and
their error expands in even powers of h (h² from the linear rod and torsion
elements, h⁴ from Hermite bending). ``fe_frequencies`` doubles the mesh and
runs a Romberg (Richardson) table per mode that removes h², h⁴, h⁶, ...; the
reported error estimate is the change made by the last extrapolation step
that was used, which bounds the error of the less extrapolated value and so
overestimates the error of the returned one in the asymptotic range. Modes
are matched by rank on each mesh: two branches that cross between meshes
usually show up as a large estimate (and more refinement). Not always: a mode
that converges too slowly to settle by the mesh cap can rank too high on every
mesh, and its rank's extrapolation then follows the next mode up with a small
change (random ring 2 at 120 modes: off by 8.5e-4, estimated 1.5e-5). So where
the refinement stops at its cap, the estimates it could not bring below rtol are
raised to the finest mesh's dispersion error (:func:`dispersion_error`), which
bounds such a mode's own error.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from time import perf_counter

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import LinearOperator, eigsh, splu

from linmstmm.mode_bound import check_range_request
from linmstmm.model import Beam, Model, Rigid
from linmstmm.results import Result, decode_array, encode_array

#: A substituted constraint row whose entries all fall below this fraction of
#: the largest term that entered it is redundant (implied by earlier rows).
REDUNDANT_CONSTRAINT = 1e-10
#: Entries below this fraction of their row's largest are rounding debris.
NEGLIGIBLE_ENTRY = 1e-14
#: A mass (kg), inertia (kg m²) or kinetic energy below this fraction of the
#: model's own scale of the same units is rounding, not mass: a body's mass or
#: principal inertia, a beam, or a rigid motion below it carries none.
MASSLESS = 1e-13
#: Eigenvalues of the mass matrix scaled to unit diagonal below this fraction of
#: the largest are the rounding of an exact zero: directions without mass.
MASS_RANK = 1e-12
#: Modes whose operator eigenvalue 1/λ is below this fraction of the largest
#: are beyond float64 resolution and treated as infinitely stiff.
UNRESOLVED_STIFFNESS = 1e-13
#: Reduced systems at most this large take the dense eigensolver.
DENSE_LIMIT = 120
#: Polishing sweeps stop when no wanted λ changes by more than this (relative).
SWEEP_TOLERANCE = 1e-14
#: A frequency whose estimated relative error is at or above this is not
#: reported (its own estimate leaves not even its first digit assured).
UNSETTLED = 0.1
#: Floor of every relative error estimate of λ (rounding of the last digits).
ROUNDOFF = 4 * np.finfo(float).eps

_TWO_PI = 2.0 * np.pi


# --------------------------------------------------------------------------
# DOF layout

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


# --------------------------------------------------------------------------
# Sparse triplets

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


# --------------------------------------------------------------------------
# Element operators

def beam_element(beam: Beam, h: float):
    """Strain operator, strain stiffnesses, mass and constraints of one element.

    Local DOFs per node ``(u, v, w, θx, θy, θz)``, node 1 then node 2 (12).

    Returns
    -------
    g : (s, 12) strains: axial stretch u₂−u₁ (m), twist θx₂−θx₁ (rad), and per
        bending plane the relative rotation and the chord-rotation defect (rad).
    d : (s,) their stiffnesses (N m or N m/rad), element energy ½ Σ d (g q)².
    m : (12, 12) consistent mass, kg and kg m².
    c : (r, 12) constraint rows (stretch if ``axial=False``, twist if
        ``torsion=False``), each ``c q = 0``.
    """
    u1, v1, w1, tx1, ty1, tz1, u2, v2, w2, tx2, ty2, tz2 = np.eye(12)
    stretch, twist = u2 - u1, tx2 - tx1
    g = [tz2 - tz1, (tz1 + tz2) / 2 - (v2 - v1) / h,      # x-y plane, EIz
         ty2 - ty1, (ty1 + ty2) / 2 + (w2 - w1) / h]      # x-z plane, EIy (θy = -w')
    d = [beam.E * beam.Iz / h, 12 * beam.E * beam.Iz / h,
         beam.E * beam.Iy / h, 12 * beam.E * beam.Iy / h]
    constraints = []
    if beam.axial:
        g.append(stretch)
        d.append(beam.E * beam.A / h)
    else:
        constraints.append(stretch)
    if beam.torsion:
        g.append(twist)
        d.append(beam.G * beam.J / h)
    else:
        constraints.append(twist)
    return (np.array(g), np.array(d), _beam_element_mass(beam, h),
            np.array(constraints).reshape(-1, 12))


def _beam_element_mass(beam: Beam, h: float) -> np.ndarray:
    """(12, 12) consistent mass of a frame element without rotary inertia."""
    rho_a = beam.rho * beam.A
    m = np.zeros((12, 12))
    bar = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
    m[np.ix_([0, 6], [0, 6])] = rho_a * h * bar                   # axial
    m[np.ix_([3, 9], [3, 9])] = beam.rho * beam.Ip * h * bar      # torsion
    hermite = rho_a * h / 420.0 * np.array([
        [156.0, 22 * h, 54.0, -13 * h],
        [22 * h, 4 * h * h, 13 * h, -3 * h * h],
        [54.0, 13 * h, 156.0, -22 * h],
        [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    m[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])] = hermite             # v, θz
    flip = np.diag([1.0, -1.0, 1.0, -1.0])                         # (w, -θy)
    m[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])] = flip @ hermite @ flip
    return m


#: A wave with kh (rod) or βh (bending) beyond this per element is not resolved by the mesh.
UNRESOLVED_WAVE = 2.0
#: Below this βh the bending dispersion error is its leading term (βh)⁴/1440 (0.44 %
#: high at βh = 0.39, about (βh)² × 3 % in general): the Bloch matrices' O(1/h³)
#: entries cancel to O(β⁴), and lose about 1e-16 · 1440 / (βh)⁸ of it (1e-5 here).
_BENDING_SERIES = 0.1


def dispersion_error(beam: Beam, h: float, omega: float) -> float:
    """Largest relative frequency error of a wave of ``omega`` (rad/s) travelling
    through a uniform mesh of this module's elements of length ``h`` (m) of ``beam``,
    over its families.

    The error a mode of that wavelength carries on that mesh, whatever its rank:
    * axial and torsion (linear, consistent mass), k = ω/c:
      ω_h = (c/h) √(12 sin²(kh/2) / (2 + cos kh)), about (kh)²/24;
    * bending in each plane (cubic Hermite, consistent mass, no rotary inertia),
      β⁴ = ω² ρA/EI: the lower Bloch branch of the periodic mesh, about (βh)⁴/1440.
    1.0 (no digit) where the mesh does not resolve the wave (kh or βh above
    UNRESOLVED_WAVE); 0 for a massless beam.
    """
    k = beam.wavenumbers(omega)
    errors = [_bending_dispersion(k[plane] * h) for plane in ("bending_y", "bending_z")]
    errors += [_rod_dispersion(k[rod] * h) for rod, deformable in (("axial", beam.axial), ("torsion", beam.torsion))
               if deformable]
    return float(max(errors))


def _rod_dispersion(kh: float) -> float:
    """Relative frequency error of linear consistent-mass rod elements at kh."""
    if kh > UNRESOLVED_WAVE:
        return 1.0
    return float(np.sqrt(12 * np.sin(kh / 2) ** 2 / (2 + np.cos(kh))) / kh - 1) if kh > 0 else 0.0


def _bending_dispersion(beta_h: float) -> float:
    """Relative frequency error of the Hermite elements' lower Bloch branch at βh."""
    if beta_h > UNRESOLVED_WAVE:
        return 1.0
    if beta_h < _BENDING_SERIES:
        return beta_h ** 4 / 1440
    g, d, m, _ = beam_element(Beam("unit", ("a", "b"), E=1.0, G=1.0, rho=1.0, A=1.0, Iy=1.0, Iz=1.0, J=1.0,
                                   Ip=1.0, axes=np.eye(3), length=1.0), 1.0)
    plane = [1, 5, 7, 11]  # (v, θz) at both nodes, EIz = 1, ρA = 1
    k = (g.T * d) @ g
    phase = np.exp(1j * beta_h)
    pair = [np.ix_(plane[:2], plane[:2]), np.ix_(plane[2:], plane[2:]),
            np.ix_(plane[:2], plane[2:]), np.ix_(plane[2:], plane[:2])]

    def periodic(matrix):
        return matrix[pair[0]] + matrix[pair[1]] + matrix[pair[2]] * phase + matrix[pair[3]] / phase

    lowest = la.eigh(periodic(k), periodic(m), eigvals_only=True)[0]
    return float(np.sqrt(lowest) / beta_h ** 2 - 1)


def _add_beams(model, layout, n, strains, stiffness, mass, constraints):
    """Scatter every beam element (vectorised over the elements of a beam)."""
    for beam in model.beams:
        nodes = layout.index.beam_nodes[beam.name]
        g, d, m, c = beam_element(beam, beam.length / n)
        to_local = np.tile(np.eye(12), (n, 1, 1))    # interior nodes: local DOFs
        axes = np.asarray(beam.axes, float)
        for block in (0, 3):                         # ends are inertial nodes
            to_local[0, block:block + 3, block:block + 3] = axes
            to_local[-1, 6 + block:9 + block, 6 + block:9 + block] = axes
        dofs = np.concatenate([6 * nodes[:-1, None] + np.arange(6),
                               6 * nodes[1:, None] + np.arange(6)], axis=1)
        g_elements = g @ to_local                              # (n, s, 12)
        rows = strains.new_rows(n * len(d)).reshape(n, len(d))
        strains.add(rows[:, :, None], dofs[:, None, :], g_elements)
        stiffness.append(np.tile(d, n))
        m_elements = np.swapaxes(to_local, 1, 2) @ m @ to_local
        mass.add(dofs[:, :, None], dofs[:, None, :], m_elements)
        if len(c):
            rows = constraints.new_rows(n * len(c)).reshape(n, len(c))
            constraints.add(rows[:, :, None], dofs[:, None, :], c @ to_local)


def _add_springs(model, layout, strains, stiffness, constraints):
    """Finite spring directions become strains, ``inf`` ones constraints, released ones nothing."""
    for spring in model.springs:
        for component, cols, values in _spring_directions(spring, layout.index, kept_only=True):
            k = float(spring.k[component])
            if np.isinf(k):
                constraints.add(constraints.new_rows(1), cols, values)
            else:
                strains.add(strains.new_rows(1), cols, values)
                stiffness.append([k])


def dashpot_matrix(model: Model, fe: FEModel) -> sp.csr_matrix:
    """(n_dof, n_dof) sparse viscous damping of the springs' dashpots ``c``.

    Assembled as the springs' stiffness is: ``C = Hᵀ diag(c) H`` with H the
    elongation of each spring direction that has a dashpot (N s/m, N m s/rad),
    in the reduced DOFs of ``fe`` (assembled from the same ``model``).
    """
    rows, damping = _Triplets(), []
    for spring in model.springs:
        for component, cols, values in _spring_directions(spring, fe.dof_index, kept_only=False):
            if spring.c is not None and spring.c[component] > 0:
                rows.add(rows.new_rows(1), cols, values)
                damping.append(float(spring.c[component]))
    H = rows.matrix(fe.n_full) @ fe.T
    return _symmetric(H.T @ sp.diags(np.asarray(damping)) @ H)


def harmonic_receptance(model: Model, point: str, vector, frequencies_hz, points,
                        elements_per_beam: int = 8, damping=None) -> np.ndarray:
    """Receptance by the direct complex solve (K + iΩ(C + αM + βK) − Ω²M) x = f.

    Parameters
    ----------
    model : the model; C holds its springs' dashpots (:func:`dashpot_matrix`).
    point : the loaded point. vector : (6,) [force N, moment N m], inertial axes.
    frequencies_hz : (n_f,) Hz. points : response point names.
    elements_per_beam : the mesh. damping : Rayleigh (α 1/s, β s) or None.

    Returns
    -------
    (n_f, n_points, 6) complex displacements (m) and rotations (rad) per unit
    of ``vector``, inertial axes: exact for springs and rigid bodies, with the
    mesh's discretisation error for beams.
    """
    fe = assemble(model, elements_per_beam)
    alpha, beta = (0.0, 0.0) if damping is None else damping
    viscous = dashpot_matrix(model, fe) + alpha * fe.M + beta * fe.K
    load = np.zeros(fe.n_full)
    load[fe.dof_index.point(point)] = vector
    load = fe.T.T @ load
    picks = np.concatenate([fe.dof_index.point(p) for p in points])
    out = np.empty((len(frequencies_hz), len(points) * 6), dtype=complex)
    for i, omega in enumerate(_TWO_PI * np.asarray(frequencies_hz, float)):
        dynamic = (fe.K + 1j * omega * viscous - omega**2 * fe.M).tocsc()
        out[i] = (fe.T @ splu(dynamic).solve(load.astype(complex)))[picks]
    return out.reshape(len(frequencies_hz), len(points), 6)


def damped_roots(model: Model, elements_per_beam: int = 8) -> np.ndarray:
    """Complex roots s (1/s) of the quadratic eigenproblem (K + sC + s²M) x = 0.

    C holds the springs' dashpots (:func:`dashpot_matrix`) and the model's
    Rayleigh ``[damping]`` αM + βK. Linearised to the generalized eigenproblem
    s [[I, 0], [0, M]] y = [[0, I], [−K, −C]] y, y = (x, s x), solved densely.

    Returns
    -------
    (m,) the finite roots with Im s > 0 (one of each conjugate pair:
    s = −ζω_n + iω_d), ascending in Im s. Massless DOFs give infinite roots,
    which are dropped; overdamped and zero (rigid-body) roots are real and
    left out.
    """
    fe = assemble(model, elements_per_beam)
    alpha, beta = (0.0, 0.0) if model.damping is None else model.damping
    damping = (dashpot_matrix(model, fe) + alpha * fe.M + beta * fe.K).toarray()
    n = fe.n_dof
    identity, zero = np.eye(n), np.zeros((n, n))
    roots = la.eigvals(np.block([[zero, identity], [-fe.K.toarray(), -damping]]),
                      np.block([[identity, zero], [zero, fe.M.toarray()]]))
    roots = roots[np.isfinite(roots) & (roots.imag > 0)]
    return roots[np.argsort(roots.imag)]


def _spring_directions(spring, index: DofIndex, kept_only: bool):
    """(component, cols (6,), values (6,)) per direction of ``spring``: the elongation
    (end b − end a along the spring's axis, m or rad) as a row on the full DOFs of ``index``.
    kept_only : leave out the released directions."""
    a, b = (_node_dofs(index.points[end]) for end in spring.ends)
    axes = np.asarray(spring.axes, float)
    for component in range(6):
        if kept_only and component in spring.released:
            continue
        block = slice(0, 3) if component < 3 else slice(3, 6)
        direction = axes[component % 3]
        yield component, np.concatenate([a[block], b[block]]), np.concatenate([-direction, direction])


def _negligible_mass_removed(model: Model) -> Model:
    """``model`` with every mass below MASSLESS of the model's own scale set to zero.

    The scales are the total mass m of bodies and beams (kg) and m d² plus the
    traces of the bodies' inertia tensors (kg m²), d the largest distance of a
    point or mass centre from their centroid (m). Each body's mass and principal
    inertias and each beam's mass are compared with the scale of their units, so
    the decision does not depend on the units a model is written in; a mass that
    is kept is exactly as given. A DOF without mass then has an exactly zero row
    and column in the assembled M.
    """
    places = np.array([*model.points.values(), *(body.com for body in model.rigids)], float)
    extent = np.linalg.norm(places - places.mean(axis=0), axis=1).max()
    total = sum(body.mass for body in model.rigids) + sum(beam.mass for beam in model.beams)
    inertia = total * extent ** 2 + sum(np.trace(body.inertia) for body in model.rigids)
    rigids = tuple(_body_mass_kept(body, MASSLESS * total, MASSLESS * inertia) for body in model.rigids)
    beams = tuple(beam if beam.mass > MASSLESS * total else replace(beam, rho=0.0) for beam in model.beams)
    if all(a is b for a, b in zip(rigids + beams, model.rigids + model.beams)):
        return model  # nothing negligible: no copy (a copy validates the whole model again)
    return replace(model, rigids=rigids, beams=beams)


def _body_mass_kept(body: Rigid, least_mass: float, least_inertia: float) -> Rigid:
    """``body`` with its mass (kg) made zero unless above ``least_mass``, and its
    principal inertias (kg m²) unless above ``least_inertia``; the same record when
    nothing changes."""
    mass = body.mass if body.mass > least_mass else 0.0
    inertia, diagonal = body.inertia, body.inertia.diagonal()
    # Gershgorin: the least of these is at most the smallest principal inertia
    gershgorin = diagonal - (np.abs(inertia).sum(axis=1) - np.abs(diagonal))
    if diagonal.any() and gershgorin.min() <= least_inertia:
        principal, axes = la.eigh(inertia)
        kept = principal > least_inertia
        if not np.all(kept | (principal == 0.0)):
            inertia = (axes * np.where(kept, principal, 0.0)) @ axes.T
    if mass == body.mass and inertia is body.inertia:
        return body
    return replace(body, mass=mass, inertia=inertia)


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


# --------------------------------------------------------------------------
# Constraint elimination

def _eliminate(constraints: sp.csr_matrix) -> sp.csr_matrix:
    """Master–slave null-space basis of the rows of ``constraints``.

    Rows are taken one at a time, written in the current masters, and one
    master becomes a slave: among the entries within a factor 2 of the
    largest (threshold pivoting), the one fewest slaves depend on, so chains
    of constraints do not fill in. Redundant rows (closed loops of rigid
    links) are recognised and skipped.

    Returns
    -------
    T1 : (n, n_masters) sparse; the masters' rows are identity rows.
    masters : (n_masters,) their indices, ascending.
    """
    n = constraints.shape[1]
    expression = {}                     # slave -> {master: coefficient}
    users = {}                          # master -> slaves that use it
    indptr, indices, data = constraints.indptr, constraints.indices, constraints.data
    for r in range(constraints.shape[0]):
        row, scale = {}, 0.0
        for j, c in zip(indices[indptr[r]:indptr[r + 1]].tolist(),
                        data[indptr[r]:indptr[r + 1]].tolist()):
            for master, e in expression.get(j, {j: 1.0}).items():
                term = c * e
                row[master] = row.get(master, 0.0) + term
                scale = max(scale, abs(term))
        largest = max((abs(v) for v in row.values()), default=0.0)
        if largest <= REDUNDANT_CONSTRAINT * scale:
            continue
        row = {m: v for m, v in row.items() if abs(v) > NEGLIGIBLE_ENTRY * largest}
        slave = min((m for m, v in row.items() if abs(v) >= 0.5 * largest),
                    key=lambda m: (len(users.get(m, ())), -abs(row[m])))
        pivot = row.pop(slave)
        solved = {m: -v / pivot for m, v in row.items()}
        for dependent in users.pop(slave, ()):
            _substitute(expression[dependent], dependent, slave, solved, users)
        expression[slave] = solved
        for master in solved:
            users.setdefault(master, set()).add(slave)
    masters = np.array(sorted(set(range(n)) - set(expression)), dtype=int)
    column = {m: i for i, m in enumerate(masters.tolist())}
    rows, cols, values = [masters], [np.arange(len(masters))], [np.ones(len(masters))]
    for slave, terms in expression.items():
        rows.append(np.full(len(terms), slave))
        cols.append(np.array([column[m] for m in terms], dtype=int))
        values.append(np.array(list(terms.values()), float))
    rows, cols, values = map(np.concatenate, (rows, cols, values))
    return sp.csr_matrix((values, (rows, cols)), shape=(n, len(masters))), masters


def _substitute(terms, owner, slave, solved, users):
    """Replace ``slave`` by its expression ``solved`` inside ``terms`` (in place)."""
    c = terms.pop(slave)
    for master, v in solved.items():
        terms[master] = terms.get(master, 0.0) + c * v
    largest = max((abs(v) for v in terms.values()), default=0.0)
    for master in [m for m, v in terms.items() if abs(v) <= NEGLIGIBLE_ENTRY * largest]:
        del terms[master]
        users.get(master, set()).discard(owner)
    for master in terms:
        users.setdefault(master, set()).add(owner)


# --------------------------------------------------------------------------
# Rigid motions

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


def _rigid_motions(model, layout) -> np.ndarray:
    """(n_full, r) zero-energy motions of each connected part: every segment
    (:func:`_components` without joints) moves rigidly, as far as the boundaries and
    the directions each joint keeps allow.

    Ports, springs and rigid axial/torsion all hold under a segment's rigid
    motion; across a joint the two segments must move alike in each direction
    it keeps. Columns are orthonormal.
    """
    labels = _components(model, layout)
    segments = _components(model, layout, through_joints=False)
    held = [sp.csr_matrix((np.ones(1), ([0], [dof])), shape=(1, 6 * layout.n_nodes))
            for point, components in model.boundary.items()
            for dof in layout.index.point(point)[np.asarray(components, bool)]]
    held += [sp.csr_matrix((values, (np.zeros(6, int), cols)), shape=(1, 6 * layout.n_nodes))
             for spring in model.springs if spring.released.size and _across_segments(spring, layout, segments)
             for _, cols, values in _spring_directions(spring, layout.index, kept_only=True)]
    held = sp.vstack(held).tocsc() if held else sp.csc_matrix((0, 6 * layout.n_nodes))
    motions = []
    for label in np.unique(labels):
        nodes = np.flatnonzero(labels == label)
        dofs = (6 * nodes[:, None] + np.arange(6)).ravel()
        field, size = _rigid_field(layout.positions[nodes], layout.frames[nodes],
                                   np.unique(segments[nodes], return_inverse=True)[1])
        weight = np.tile(np.r_[np.ones(3), np.full(3, size)], len(nodes))  # rotation rows of order one
        rows = held[:, dofs]
        rows = rows[np.flatnonzero(np.diff(rows.tocsr().indptr))]  # the rows on this part
        allowed = (la.null_space(rows @ (weight[:, None] * field), rcond=REDUNDANT_CONSTRAINT)
                   if rows.shape[0] else np.eye(field.shape[1]))
        if allowed.shape[1]:
            motion = np.zeros((6 * layout.n_nodes, allowed.shape[1]))
            motion[dofs] = la.orth(field @ allowed)
            motions.append(motion)
    return np.hstack(motions) if motions else np.zeros((6 * layout.n_nodes, 0))


# --------------------------------------------------------------------------
# Assembly

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
    layout = _layout(model, n)
    n_full = 6 * layout.n_nodes
    strains, mass, constraints = _Triplets(), _Triplets(), _Triplets()
    stiffness = []
    _add_beams(model, layout, n, strains, stiffness, mass, constraints)
    _add_springs(model, layout, strains, stiffness, constraints)
    _add_rigid_masses(model, layout, mass)
    _add_boundaries(model, layout, constraints)
    t0, q0_dofs = _port_map(model, layout, constraints)

    reduced_constraints = _drop_debris(constraints.matrix(n_full) @ t0)
    t1, masters = _eliminate(reduced_constraints)
    T = (t0 @ t1).tocsr()
    masters = q0_dofs[masters]

    G = (strains.matrix(n_full) @ T).tocsr()
    D = np.concatenate(stiffness) if stiffness else np.zeros(0)
    M = _symmetric(T.T @ mass.matrix(n_full, n_full) @ T)
    K = _symmetric(G.T @ sp.diags(D) @ G)
    rigid_modes, supports = _rigid_basis(_rigid_motions(model, layout)[masters], M)
    return FEModel(M=M, K=K, T=T, G=G, D=D, dof_index=layout.index,
                   n_dof=T.shape[1], n_full=n_full, elements_per_beam=n,
                   rigid_modes=rigid_modes, supports=supports, frames=layout.frames,
                   massive=np.flatnonzero(M.diagonal()))


def _drop_debris(matrix) -> sp.csr_matrix:
    """``matrix`` without entries below NEGLIGIBLE_ENTRY of their row's largest."""
    matrix = sp.csr_matrix(matrix)
    matrix.sum_duplicates()
    magnitude = np.abs(matrix.data)
    row_of = np.repeat(np.arange(matrix.shape[0]), np.diff(matrix.indptr))
    row_max = np.zeros(matrix.shape[0])
    np.maximum.at(row_max, row_of, magnitude)
    matrix.data[magnitude <= NEGLIGIBLE_ENTRY * row_max[row_of]] = 0.0
    matrix.eliminate_zeros()
    return matrix


def _symmetric(matrix) -> sp.csr_matrix:
    return ((matrix + matrix.T) * 0.5).tocsr()


def _rigid_basis(motions, M):
    """Massive rigid-body modes (M-orthonormal) and supports that stop all motions.

    motions : (n_dof, r) rigid motions in reduced DOFs.

    Returns
    -------
    modes : (n_dof, r_massive) with ``modes.T @ M @ modes = I``.
    supports : (r,) DOFs on which the motions are independent (pivoted QR).
    """
    n = M.shape[0]
    if motions.shape[1] == 0:
        return np.zeros((n, 0)), np.zeros(0, dtype=int)
    basis = la.orth(motions)
    kinetic, directions = la.eigh(basis.T @ (M @ basis))
    # against the model's own mass scale too: a joint can leave a motion of massless
    # points alone, whose kinetic energy is the rounding of the others' DOFs
    massive = kinetic > MASSLESS * max(np.abs(kinetic).max(), M.diagonal().max())
    modes = basis @ (directions[:, massive] / np.sqrt(kinetic[massive]))
    pivots = la.qr(basis.T, pivoting=True, mode="r")[1]
    return modes, np.sort(pivots[:basis.shape[1]])


# --------------------------------------------------------------------------
# Eigensolver

class _Flexibility:
    """``f -> P K⁺ Pᵀ f``: static response to loads, rigid-body modes deflated.

    K is never factorised: the solve uses the mixed system
    ``[[-D⁻¹, G], [Gᵀ, 0]] [s; y] = [0; f]`` (s = element forces) on the DOFs
    left free by the temporary supports. ``P = I - R Rᵀ M`` removes the
    rigid-body modes R, so ``K⁺M`` has eigenvalues 1/λ for elastic modes and
    0 for rigid-body modes and massless DOFs.
    """

    def __init__(self, fe: FEModel):
        self.fe = fe
        self.free = np.setdiff1d(np.arange(fe.n_dof), fe.supports)
        self.n_strain = len(fe.D)
        self.lu = None
        if len(self.free):
            g = fe.G[:, self.free]
            mixed = sp.bmat([[sp.diags(-1.0 / fe.D), g], [g.T, None]], format="csc")
            try:
                self.lu = splu(mixed)
            except RuntimeError as error:
                raise ValueError(
                    f"{fe.n_dof}-DOF model: the stiffness is singular beyond its rigid-body "
                    f"modes (a motion with neither stiffness nor support): {error}") from None

    def __call__(self, f: np.ndarray) -> np.ndarray:
        """f : (n_dof,) or (n_dof, b) loads; returns displacements of the same shape."""
        fe, modes = self.fe, self.fe.rigid_modes
        loads = np.asarray(f, float).reshape(fe.n_dof, -1)
        loads = loads - fe.M @ (modes @ (modes.T @ loads))
        y = np.zeros_like(loads)
        if self.lu is not None:
            rhs = np.zeros((self.n_strain + len(self.free), loads.shape[1]))
            rhs[self.n_strain:] = loads[self.free]
            y[self.free] = self.lu.solve(rhs)[self.n_strain:]
        y -= modes @ (modes.T @ (fe.M @ y))
        return y.reshape(np.shape(f))


def static_displacements(model: Model, loads, points, elements_per_beam: int = 1) -> np.ndarray:
    """Elastic static displacements of ``points`` under each point load, K⁺ f.

    Hermite beam elements give the exact static solution at their nodes for
    point loads, so one element per beam suffices for a held model. A model
    with rigid-body modes is solved for its elastic part: the load's
    rigid-body part is removed and so is the rigid-body motion of the result
    (M-orthogonal to the rigid-body modes, as the elastic modes are); that
    last step weighs the beams' interpolated fields with the mesh's mass, so
    with beams it converges with the mesh instead of being exact.

    Parameters
    ----------
    model : the model records.
    loads : sequence of (point name, (6,) [force N, moment N m]) in inertial axes.
    points : sequence of point names to report.
    elements_per_beam : int >= 1.

    Returns
    -------
    (n_loads, n_points, 6) displacements m and rotations rad, inertial axes.
    """
    fe = assemble(model, elements_per_beam)
    full = np.zeros((fe.n_full, len(loads)))
    for i, (point, vector) in enumerate(loads):
        full[fe.dof_index.point(point), i] = vector
    motion = (fe.T @ _Flexibility(fe)(fe.T.T @ full)).T  # (n_loads, n_full)
    return np.stack([motion[:, fe.dof_index.point(p)] for p in points], axis=1)


def _rayleigh_ritz(fe: FEModel, Y: np.ndarray):
    """Ritz pairs of span(Y), energies from strains.

    Returns ascending λ (rad²/s²) and mass-normalised vectors (n_dof, m);
    directions of span(Y) without mass are dropped.
    """
    MY = fe.M @ Y
    norms = np.sqrt(np.maximum(np.einsum("ij,ij->j", Y, MY), 0.0))
    keep = norms > 0.0
    Y = Y[:, keep] / norms[keep]
    gram = Y.T @ (fe.M @ Y)
    weights, directions = la.eigh(0.5 * (gram + gram.T))
    keep = weights > 1e-12 * weights[-1]          # drop numerically dependent directions
    Z = Y @ (directions[:, keep] / np.sqrt(weights[keep]))
    strains = np.sqrt(fe.D)[:, None] * (fe.G @ Z)
    _, C = la.eigh(strains.T @ strains)
    X = Z @ C
    X /= np.sqrt(np.einsum("ij,ij->j", X, fe.M @ X))
    lam = np.sum((np.sqrt(fe.D)[:, None] * (fe.G @ X)) ** 2, axis=0)
    order = np.argsort(lam)
    return lam[order], X[:, order]


def _mass_factor(fe: FEModel) -> np.ndarray:
    """(n_dof, r) B with ``M = B Bᵀ``, r = rank M: the directions that carry mass.

    Only the massive DOFs enter. Their block of M is scaled to unit diagonal, so
    that translations (kg) and rotations (kg m²) weigh alike whatever the units;
    its eigenvalues below MASS_RANK of the largest are the rounding of exact zeros
    (directions without mass across DOFs, as of a singular inertia tensor in skew
    axes) and are left out.
    """
    block = fe.M[fe.massive][:, fe.massive].toarray()
    size = np.sqrt(block.diagonal())
    values, vectors = la.eigh(block / np.outer(size, size))
    kept = values > MASS_RANK * values.max(initial=0.0)
    factor = np.zeros((fe.n_dof, np.count_nonzero(kept)))
    factor[fe.massive] = size[:, None] * vectors[:, kept] * np.sqrt(values[kept])
    return factor


def _dense_start(fe: FEModel, flexibility) -> np.ndarray:
    """All resolvable elastic modes of a small model, approximately, softest first.

    Static condensation of the massless DOFs, which is exact (they have no
    inertia): with ``M = B Bᵀ`` (:func:`_mass_factor`) the condensed flexibility
    ``Bᵀ K⁺ B`` (r x r) has eigenvalues 1/λ for the elastic modes and 0 for the
    rigid-body modes, and a mode is ``x = K⁺ B z λ``, its massless DOFs
    following statically. There are exactly r − (rigid-body modes) elastic
    modes, so no eigenvalue of a massless direction is ever mistaken for one.
    """
    factor = _mass_factor(fe)
    elastic = factor.shape[1] - fe.rigid_modes.shape[1]
    if elastic <= 0:
        return np.zeros((fe.n_dof, 0))
    flexible = flexibility(factor)
    condensed = factor.T @ flexible
    theta, Z = la.eigh(0.5 * (condensed + condensed.T))
    theta, Z = theta[::-1][:elastic], Z[:, ::-1][:, :elastic]
    keep = theta > UNRESOLVED_STIFFNESS * max(theta[0], 0.0)
    return (flexible @ Z[:, keep]) / theta[keep]


def _lanczos_start(fe: FEModel, flexibility, block: int) -> np.ndarray:
    """The ``block`` lowest elastic modes, approximately, by ARPACK on K⁺M."""
    n = fe.n_dof
    operator = LinearOperator((n, n), matvec=flexibility, dtype=float)
    start = np.random.default_rng(0).standard_normal(n)
    _, X = eigsh(fe.K, k=block, M=fe.M, sigma=0.0, which="LM", OPinv=operator,
                 v0=start, ncv=_lanczos_vectors(n, block))
    return X


def _lanczos_vectors(n_dof: int, block: int) -> int:
    """ARPACK's ``ncv`` for ``block`` modes of an ``n_dof`` model."""
    return min(n_dof, max(2 * block + 1, 20))


def _massive_dofs(fe: FEModel) -> int:
    """DOFs that carry mass, less the rigid-body modes: at least the number of
    elastic modes and the rank of K⁺M. A Krylov space of K⁺M cannot grow past
    that rank, so ARPACK asked for more vectors than that stops ("could not build
    an Arnoldi factorization": random trees at 80 modes, 204 DOFs of which 198
    carry mass, 201 vectors)."""
    return len(fe.massive) - fe.rigid_modes.shape[1]


def _block_size(wanted: int) -> int:
    """Wanted modes plus guard vectors, so an edge cluster is not split."""
    return wanted + max(4, wanted // 4)


def _lowest_modes(fe: FEModel, flexibility, wanted: int, sweeps: int = 8):
    """The ``wanted`` lowest elastic modes, polished by subspace iteration.

    A block of :func:`_block_size` vectors is started by Lanczos (densely for
    small models) and refined by inverse iteration with Rayleigh–Ritz in the
    natural factor until the wanted λ stop changing.

    Returns ascending λ (rad²/s²) of the whole block, mass-normalised vectors
    (n_dof, m), and per λ the relative change in the last sweep (the solver
    error estimate). m is below the block size when the model has fewer
    elastic modes.
    """
    block = min(_block_size(wanted), _massive_dofs(fe))
    if block <= 0:
        X = np.zeros((fe.n_dof, 0))
    elif fe.n_dof <= DENSE_LIMIT or _lanczos_vectors(fe.n_dof, block) >= _massive_dofs(fe):
        X = _dense_start(fe, flexibility)[:, :block]
    else:
        X = _lanczos_start(fe, flexibility, block)
    if X.shape[1] == 0:
        return np.zeros(0), X, np.zeros(0)
    lam, X = _rayleigh_ritz(fe, flexibility(fe.M @ X))
    for _ in range(sweeps):
        new_lam, X = _rayleigh_ritz(fe, flexibility(fe.M @ X))
        m = min(len(lam), len(new_lam))
        change = np.abs(new_lam[:m] - lam[:m]) / new_lam[:m]
        lam, X = new_lam[:m], X[:, :m]
        if change[:wanted].max(initial=0.0) <= SWEEP_TOLERANCE:
            break
    return lam, X, change


def fe_modes(fe: FEModel, count=10, lam_max=None, at_least=0):
    """Lowest elastic eigenpairs of an assembled model.

    Parameters
    ----------
    count : int or None, the lowest ``count`` modes.
    lam_max : float or None, all modes with ω² <= lam_max (rad²/s²).
        Both given: whichever stops first; neither: the lowest 10.
    at_least : int, return at least this many (if the model has them).

    Returns
    -------
    lam : (m,) ascending ω², rad²/s².
    X : (n_dof, m) mass-normalised reduced mode shapes.
    solver_error : (m,) relative change of λ in the last polishing sweep.
    """
    flexibility = _Flexibility(fe)
    wanted = max(count or 10, at_least)
    while True:
        lam, X, change = _lowest_modes(fe, flexibility, wanted)
        found_all = len(lam) < _block_size(wanted)
        if count is not None or lam_max is None or found_all or lam[wanted - 1] > lam_max:
            break
        wanted *= 2
    keep = len(lam) if count is None else max(count, at_least)
    if lam_max is not None:
        keep = min(keep, max(np.searchsorted(lam, lam_max, side="right"), at_least))
    return lam[:keep], X[:, :keep], change[:keep]


# --------------------------------------------------------------------------
# Frequencies with mesh refinement

@dataclass(frozen=True, eq=False)
class FEResult(Result):
    """Natural frequencies by the finite-element route.

    frequencies_hz : (m,) elastic natural frequencies, ascending, Hz, each
        repeated per multiplicity.
    rigid_body_modes : number of zero-frequency modes (not in the list).
    error_estimate : (m,) estimated relative error of each frequency
        (discretisation and solver); NaN where it could not be estimated.
    elements_per_beam : finest mesh used (None for a model without beams).
    n_dof : reduced DOFs of that mesh. seconds : wall time of the whole solve.
    mode_shapes : (n_full, m) mass-normalised full vectors on that mesh (see
        :class:`DofIndex` for the layout), or None.
    note : empty, or, joined by "; ": the computed values not reported because
        their estimated relative error is UNSETTLED (10 %) or more, with all
        above them; the frequencies less accurate than asked where the
        refinement stopped at ``max_elements_per_beam`` with their estimated
        error above ``rtol``; that a model without beams has fewer elastic
        modes than asked for.
    """

    model: str
    frequencies_hz: np.ndarray
    rigid_body_modes: int
    error_estimate: np.ndarray
    elements_per_beam: int | None
    n_dof: int
    seconds: float
    mode_shapes: np.ndarray | None = None
    note: str = ""

    kind = "fe"

    def to_dict(self) -> dict:
        """JSON-ready summary (the ``freqs --json`` keys plus the FE ones).

        Returns
        -------
        dict
            ``model``, ``frequencies_hz``, ``rigid_body_modes``, ``n_dof``, ``elements_per_beam``,
            ``error_estimate``, ``seconds``, ``method`` and, when set, ``note``.
        """
        return {"model": self.model,
                "frequencies_hz": [float(f) for f in self.frequencies_hz],
                "rigid_body_modes": int(self.rigid_body_modes),
                "n_dof": int(self.n_dof),
                "elements_per_beam": self.elements_per_beam,
                "error_estimate": [float(e) for e in self.error_estimate],
                "seconds": float(self.seconds),
                "method": "fe",
                **({"note": self.note} if self.note else {})}

    def _restoring_dict(self) -> dict:
        """The mode shapes :meth:`to_dict` leaves out (None when not computed)."""
        return {"mode_shapes": None if self.mode_shapes is None else encode_array(self.mode_shapes)}

    @classmethod
    def _from_data(cls, data: dict) -> FEResult:
        """The result :meth:`~linmstmm.results.Result.to_record` describes."""
        shapes = data["mode_shapes"]
        return cls(data["model"], decode_array(data["frequencies_hz"]), data["rigid_body_modes"],
                   decode_array(data["error_estimate"]), data["elements_per_beam"], data["n_dof"], data["seconds"],
                   None if shapes is None else decode_array(shapes, ndim=2), data.get("note", ""))

    def plot(self):
        """Draw the frequencies against their mode number and, on a second axis, their estimated errors.

        Returns
        -------
        matplotlib.figure.Figure
            Unsaved (:func:`linmstmm.plot.frequency_figure` with ``error_estimate``).
        """
        from linmstmm.plot import frequency_figure

        return frequency_figure(self.frequencies_hz, self.rigid_body_modes, self.error_estimate,
                                title=f"{self.model}: natural frequencies (finite elements)")


def _romberg(values, max_order: int = 4):
    """Richardson extrapolation of one eigenvalue over meshes h, h/2, h/4, ...

    The error is taken to expand as Σ c_k h^(2k); column q of the table
    removes h^(2q). Of the finest row, only entries whose column also has an
    entry one mesh coarser are candidates (the newest, top column is not yet
    checked); each one's error estimate is the larger of its differences from
    the entry one order lower and from that coarser entry, and the candidate
    with the smallest estimate is returned.

    Returns (value, absolute error estimate); the estimate is inf for one mesh.
    """
    previous, row = [], [values[0]]
    for j in range(1, len(values)):
        previous, row = row, [values[j]]
        for q in range(1, min(j, max_order) + 1):
            row.append(row[q - 1] + (row[q - 1] - previous[q - 1]) / (4 ** q - 1))
    best, best_error = row[0], np.inf
    for q in range(1, min(len(row), max(len(previous), 2))):
        error = abs(row[q] - row[q - 1])
        if q < len(previous):
            error = max(error, abs(row[q] - previous[q]))
        if error < best_error:
            best, best_error = row[q], error
    return best, best_error


def _extrapolate(levels):
    """Per mode of the finest level: Romberg over the meshes that have it.

    levels : list of ascending λ arrays, coarse to fine, mesh doubled each time.
    Returns extrapolated λ and their relative error estimates.
    """
    finest = levels[-1]
    lam, error = finest.copy(), np.full(len(finest), np.inf)
    for i in range(len(finest)):
        history = []
        for level in reversed(levels):
            if len(level) <= i:
                break
            history.insert(0, level[i])
        value, absolute = _romberg(history)
        lam[i], error[i] = value, absolute / abs(value)
    return lam, error


def fe_frequencies(model: Model, count=10, fmax=None, elements_per_beam=None,
                   rtol: float = 1e-9, *, estimate_error: bool = True,
                   max_elements_per_beam: int = 1024, mode_shapes: bool = False) -> FEResult:
    """Elastic natural frequencies of ``model`` by finite elements.

    Parameters
    ----------
    model : Model
        The model.
    count : int or None
        The lowest ``count`` frequencies.
    fmax : float or None
        All frequencies up to ``fmax`` Hz. Both: whichever stops first;
        neither: ``count = 10``.
    elements_per_beam : int or None
        None = refine: double the mesh from 4 elements per beam,
        Richardson-extrapolate each frequency, and stop when every estimated
        relative error is <= ``rtol`` (at least three meshes) or the next
        mesh would exceed ``max_elements_per_beam``. An int = that mesh, no
        extrapolation; its error is estimated from one solve on half the mesh
        unless ``estimate_error`` is False (then NaN).
    rtol : float
        Target relative error of the frequencies when refining.
    estimate_error : bool
        With a fixed mesh: estimate the error from half the mesh.
    max_elements_per_beam : int
        The finest mesh the refinement may reach.
    mode_shapes : bool
        Also return mass-normalised full mode vectors.

    Returns
    -------
    FEResult

    Zero-frequency rigid-body modes are counted structurally (see the module
    notes), not by a threshold on computed eigenvalues. No value whose estimated
    relative error is UNSETTLED (10 %) or more is reported as a frequency, nor
    any above it: the result stops before it and its note names them. ``fmax`` alone is checked
    as :func:`linmstmm.solve.natural_frequencies` checks it (ModelError).
    """
    started = perf_counter()
    if count is None and fmax is None:
        count = 10
    if count is None:
        check_range_request(model, fmax)
    lam_max = None if fmax is None else (_TWO_PI * fmax) ** 2
    if not model.beams:
        fe = assemble(model, 1)
        lam, X, lam_error = fe_modes(fe, count, lam_max)
    elif elements_per_beam is not None:
        fe, lam, X, lam_error = _fixed_mesh(model, elements_per_beam, count, lam_max,
                                            estimate_error)
    else:
        fe, lam, X, lam_error = _refine(model, count, lam_max, rtol, max_elements_per_beam)
    keep = np.ones(len(lam), bool) if lam_max is None else lam <= lam_max
    lam, X, lam_error = lam[keep][:count], X[:, keep][:, :count], lam_error[keep][:count]
    order = np.argsort(lam)
    frequencies_hz, error_estimate = np.sqrt(lam[order]) / _TWO_PI, np.maximum(lam_error[order], ROUNDOFF) / 2
    refined = bool(model.beams) and elements_per_beam is None
    if refined:
        error_estimate = _with_dispersion(model, fe.elements_per_beam, frequencies_hz, error_estimate, rtol)
    settled = _settled_count(error_estimate)
    notes = [_unsettled(frequencies_hz[settled:], error_estimate[settled:])]
    frequencies_hz, error_estimate, order = frequencies_hz[:settled], error_estimate[:settled], order[:settled]
    if refined:
        notes.append(_short_of_rtol(frequencies_hz, error_estimate, rtol, fe.elements_per_beam))
    if not model.beams and fmax is None and len(lam) < count:
        notes.append(f"only {len(lam)} elastic natural frequencies exist (directions with mass "
                     f"less the {fe.rigid_modes.shape[1]} rigid-body modes)")
    return FEResult(model=model.name,
                    frequencies_hz=frequencies_hz,
                    rigid_body_modes=fe.rigid_modes.shape[1],
                    error_estimate=error_estimate,
                    elements_per_beam=fe.elements_per_beam if model.beams else None,
                    n_dof=fe.n_dof,
                    seconds=perf_counter() - started,
                    mode_shapes=(fe.T @ X[:, order]) if mode_shapes else None,
                    note="; ".join(note for note in notes if note))


def _settled_count(error_estimate) -> int:
    """How many of the ascending frequencies are reported: those before the first
    whose estimated relative error is UNSETTLED or more. The ones above it are not
    reported either, since a list with a gap would misstate their ranks. A NaN
    estimate (not asked for) does not stop the list."""
    unsettled = np.flatnonzero(error_estimate >= UNSETTLED)
    return int(unsettled[0]) if len(unsettled) else len(error_estimate)


def _unsettled(frequencies_hz, error_estimate) -> str:
    """The note naming frequencies left out of a result (empty if none is)."""
    if not len(frequencies_hz):
        return ""
    listed = ", ".join(f"{f:.6g} Hz ({e:.1e})" for f, e in zip(frequencies_hz[:5], error_estimate[:5]))
    more = f" and {len(frequencies_hz) - 5} more" if len(frequencies_hz) > 5 else ""
    return (f"{len(frequencies_hz)} computed values not reported as frequencies, from the first whose "
            f"estimated relative error is {UNSETTLED:.0%} or more: {listed}{more}")


def _with_dispersion(model, elements_per_beam, frequencies_hz, error_estimate, rtol):
    """``error_estimate`` with those above ``rtol`` (a refinement stopped at its mesh
    cap) raised to the elements' dispersion error on the finest mesh at their
    frequency, the largest over the beams (:func:`dispersion_error`).

    Modes are matched by rank across meshes. A mode that converges too slowly
    to settle by the cap (a high torsion mode of linear elements) can rank above
    its true place on every mesh, so that the rank it should hold is held by the
    next mode up and the extrapolation is of the wrong mode, with a small change
    between meshes: random ring 2 at 120 modes reported its 120th frequency 8.5e-4
    off with an estimate of 1.5e-5. The reported value is then off by at most the
    hidden mode's own error, which the dispersion error of the finest mesh bounds.
    """
    short = error_estimate > rtol
    if not short.any():
        return error_estimate
    dispersion = [max(dispersion_error(beam, beam.length / elements_per_beam, _TWO_PI * f) for beam in model.beams)
                  for f in frequencies_hz[short]]
    raised = error_estimate.copy()
    raised[short] = np.maximum(error_estimate[short], dispersion)
    return raised


def _short_of_rtol(frequencies_hz, error_estimate, rtol, elements_per_beam) -> str:
    """The note of a refinement that stopped at its mesh cap with estimates above ``rtol``
    (empty if none is)."""
    short = np.flatnonzero(error_estimate > rtol)
    if not len(short):
        return ""
    listed = ", ".join(f"{frequencies_hz[i]:.6g} Hz ({error_estimate[i]:.1e})" for i in short[:5])
    more = f" and {len(short) - 5} more" if len(short) > 5 else ""
    return (f"mesh refinement stopped at {elements_per_beam} elements per beam (max_elements_per_beam) "
            f"with {len(short)} frequencies above rtol = {rtol:.0e} (estimated relative error, at least the "
            f"elements' dispersion error on that mesh): {listed}{more}")


def _fixed_mesh(model, elements_per_beam, count, lam_max, estimate_error):
    """One mesh; error from the change against half the mesh, taken as if
    second order (``|λ_n − λ_n/2| / 3``), which overestimates the h⁴ bending
    error about fivefold.

    Returns the FEModel, λ, mode vectors and relative error estimates of λ.
    """
    fe = assemble(model, elements_per_beam)
    lam, X, solver = fe_modes(fe, count, lam_max)
    lam_error = np.full(len(lam), np.nan)
    if estimate_error and fe.elements_per_beam >= 2:
        coarse = fe_modes(assemble(model, fe.elements_per_beam // 2),
                          count, lam_max, at_least=len(lam))[0][:len(lam)]
        m = len(coarse)
        lam_error[:m] = np.abs(coarse - lam[:m]) / (3 * lam[:m])
    return fe, lam, X, np.maximum(lam_error, solver)


def _refine(model, count, lam_max, rtol, max_elements_per_beam):
    """Mesh doubling with Richardson extrapolation; see :func:`fe_frequencies`.

    Returns the finest FEModel, extrapolated λ, its mode vectors and the
    relative error estimates of λ.
    """
    level_lam_max = None if lam_max is None else 1.5 * lam_max
    levels, n = [], 4
    while True:
        fe = assemble(model, n)
        lam, X, solver = fe_modes(fe, count, level_lam_max,
                                  at_least=len(levels[-1]) if levels else 0)
        levels.append(lam)
        extrapolated, error = _extrapolate(levels)
        error = np.maximum(error, solver)
        reported = np.ones(len(lam), bool) if lam_max is None else extrapolated <= lam_max
        if count is not None:
            reported[count:] = False
        converged = len(levels) >= 3 and np.all(error[reported] / 2 <= rtol)
        if converged or 2 * n > max_elements_per_beam:
            return fe, extrapolated, X, error
        n *= 2
