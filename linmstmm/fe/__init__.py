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
  ``λ = |D^½ G x|² / xᵀ M x``, never from ``xᵀ K x``; the strains are those
  of each solve's displacements before the rigid-body modes are deflated,
  carried through the Rayleigh–Ritz combinations. A vector with the
  rigid-body modes subtracted holds their rounding, which a stiff element's
  chord rotation (w₂ − w₁)/h magnifies 1/h times (a floating loop at 1024
  elements per beam had its second frequency 1.5e-9 high that way).

Lanczos (ARPACK) on the operator ``K⁺M`` supplies approximate modes; a few
sweeps of subspace (inverse) iteration with Rayleigh–Ritz in the natural
factor (each direction of the basis normalised by its own M-norm, so that one
inverse iteration has shrunk by 1e-11 is kept) then give eigenvalues whose
rounding error stays near 1e-14 relative
even at a thousand elements per beam (against the exact eigenvalues of the
same mesh in mpmath, tests/test_fe_rounding.py).

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
first (:mod:`linmstmm.fe.masses`), so such DOFs have zero rows in M.
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

Modules
-------
* :mod:`~linmstmm.fe.layout` — node numbering, DOF layout, sparse triplets;
* :mod:`~linmstmm.fe.sparse` — sparse matrices built straight from their entries;
* :mod:`~linmstmm.fe.products` — small models' products formed densely, summed as
  scipy.sparse sums them (the same matrices bit for bit, without its per-call cost);
* :mod:`~linmstmm.fe.elements` — the frame element and its dispersion error;
* :mod:`~linmstmm.fe.masses` — negligible masses removed;
* :mod:`~linmstmm.fe.constraints` — master–slave constraint elimination;
* :mod:`~linmstmm.fe.node_constraints` — the springs, boundaries, ports and rigid
  masses on the model's nodes and their constraints' elimination, made once per
  model and extended to any mesh;
* :mod:`~linmstmm.fe.rigid_motions` — rigid-body modes counted structurally;
* :mod:`~linmstmm.fe.assembly` — :class:`FEModel` and :func:`assemble`;
* :mod:`~linmstmm.fe.flexibility` — K⁺ by the mixed system, static displacements;
* :mod:`~linmstmm.fe.condensation` — static condensation of massless DOFs;
* :mod:`~linmstmm.fe.eigensolver` — Lanczos and subspace iteration (:func:`fe_modes`);
* :mod:`~linmstmm.fe.richardson` — Romberg extrapolation over meshes;
* :mod:`~linmstmm.fe.frequencies` — :func:`fe_frequencies`, mesh refinement;
* :mod:`~linmstmm.fe.result` — :class:`FEResult`;
* :mod:`~linmstmm.fe.damping` — dashpots, direct receptance, complex roots.

The names below are imported from their module on first use, so that a module
of the route (``linmstmm.fe.node_constraints``, which the transfer-matrix
code's coarse prediction and counter share) loads without the rest of it.
"""

from __future__ import annotations

import importlib

#: Public name -> the module of the route that defines it.
_SOURCES = {
    "FEModel": "assembly", "assemble": "assembly",
    "MASS_RANK": "condensation", "UNRESOLVED_STIFFNESS": "condensation",
    "NEGLIGIBLE_ENTRY": "constraints", "REDUNDANT_CONSTRAINT": "constraints",
    "damped_roots": "damping", "dashpot_matrix": "damping", "harmonic_receptance": "damping",
    "DENSE_LIMIT": "eigensolver", "SWEEP_TOLERANCE": "eigensolver", "fe_modes": "eigensolver",
    "UNRESOLVED_WAVE": "elements", "beam_element": "elements", "dispersion_error": "elements",
    "static_displacements": "flexibility",
    "ROUNDOFF": "frequencies", "UNSETTLED": "frequencies", "fe_frequencies": "frequencies",
    "DofIndex": "layout",
    "MASSLESS": "masses",
    "FEResult": "result",
}

__all__ = sorted(_SOURCES)


def __getattr__(name: str):
    """Import a public name from its module on first use (PEP 562)."""
    if name not in _SOURCES:
        raise AttributeError(f"module 'linmstmm.fe' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"linmstmm.fe.{_SOURCES[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the public ones included before their first use."""
    return sorted(set(globals()) | set(__all__))
