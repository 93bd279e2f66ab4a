"""Mode shapes, augmented eigenvectors and their orthogonality (docs/method.md).

At a natural frequency ω the null space of Ū_all(ω) holds the boundary
unknowns z̄ of the modes (a whole basis for a repeated frequency). The element
transfer equations then give the state vector at every port, and the beam
transfer matrix over part of a beam gives the field inside each beam.

The *augmented eigenvector* V^k collects the modal displacements of every
body: the mass-centre translation and rotation of each rigid body, the
displacement and rotation fields along each beam. With the body operators

* mass: rigid body m (translation) and J_c (rotation); beam ρA for the three
  translations and ρIp for the torsional rotation (no rotary inertia in
  bending), integrated along the beam by Gauss–Legendre quadrature;
* stiffness: springs ½ Δᵀ K Δ with Δ = (end b − end a) in the spring's axes
  (``inf`` directions carry no energy); beams the strain energy
  ½ ∫ (m_y²/EI_y + m_z²/EI_z + q_x²/EA + m_x²/GJ) dx written with the
  internal forces of the state vector (= EI v''² + EA u'² + GJ θ'²),

the inner products ⟨M V^k, V^p⟩ = δ_kp M_k and ⟨K V^k, V^p⟩ = δ_kp K_k hold;
both matrices are computed and reported, so their off-diagonal terms measure
the accuracy of the modes. Within a repeated frequency the basis is made
mass-orthonormal by the eigen-decomposition of its small mass matrix.

Units: displacements m, rotations rad, states as in the package
(``Z = [X, Y, Z, Θx, Θy, Θz, Mx, My, Mz, Qx, Qy, Qz]``); a mass-normalised
mode has M_k = 1 kg, so its amplitudes are in m/√kg.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from linmstmm.deduction import Deduction
from linmstmm.elements.beam import beam_transfer
from linmstmm.model import Model, ModelError
from linmstmm.nullspace import NULL_TOLERANCE, equilibration
from linmstmm.solve import search_note, solve_roots
from linmstmm.stages import report
from linmstmm.threads import single_blas_thread

#: Normalisations of the modes: unit modal mass, or unit largest translation.
NORMALIZATIONS = ("mass", "max")
#: The one default, of :func:`mode_shapes` and of ``linmstmm modes``: unit modal mass.
DEFAULT_NORMALIZATION = "mass"
#: Frequencies closer than this (relative) are one repeated frequency.
SAME_FREQUENCY = 1e-9
#: Relative frequency offset of the matrices that scale Ū_all for its null space.
SCALE_PROBE = 1e-3
#: Mode shapes whose mass orthogonality or Rayleigh quotient is off by more than this
#: (relative) are named in the result's note (a free beam's 30th mode, βL = 36, was
#: off by 1e-2 and its 60th by 100 %, without a word).
SHAPE_ACCURACY = 1e-4
#: Gauss–Legendre points along a beam beyond its largest wavenumber × length.
EXTRA_QUADRATURE_POINTS = 20
#: A mode "has no translation" when its largest translation is below this
#: fraction of (largest rotation × model size); it is then scaled by rotation.
_TRANSLATION_FLOOR = 1e-9
#: Weights of the x, y, z translational mass that orient a repeated frequency's basis.
_AXIS_WEIGHTS = np.array([1.0, 2.0, 3.0])


@dataclass(frozen=True, eq=False)
class BeamField:
    """Modal field inside one beam.

    stations : (s,) distance from ``ends[0]``, m.
    positions : (s, 3) station positions, m, inertial frame.
    displacements : (n_modes, s, 6) translation (m) and rotation (rad), inertial.
    """

    stations: np.ndarray
    positions: np.ndarray
    displacements: np.ndarray


@dataclass(frozen=True, eq=False)
class ModalResult:
    """Modes of a model, ascending in frequency (rigid-body modes first).

    omega : (n,) rad/s; ``frequencies_hz`` (n,) Hz.
    rigid_body_modes : number of zero-frequency modes at the start.
    modal_mass : (n,) M_k = ⟨M V^k, V^k⟩ (1 for mass normalisation).
    modal_stiffness : (n,) K_k = ω_k² M_k.
    orthogonality_mass : (n, n) ⟨M V^k, V^p⟩ / √(M_k M_p): ideally the identity.
    orthogonality_stiffness : (n, n) ⟨K V^k, V^p⟩ / √(M_k M_p): ideally diag(ω²).
    boundary_unknowns : (n, N) z̄ of each mode; ``unknown_labels`` names its columns.
    port_states : "element@point" -> (n, 12) state at that port of the transfer
        element (forces: what the element's upstream side exerts downstream).
    point_displacements : point -> (n, 6).
    com_displacements : rigid body -> (n, 6) at its mass centre.
    beam_fields : beam -> :class:`BeamField`.
    normalization : "mass" or "max" (largest translation of each mode = 1 m).
    note : what the search must say ("" if nothing; see :func:`linmstmm.solve.search_note`), and
        which shapes float64 did not form to SHAPE_ACCURACY.
    """

    model: str
    omega: np.ndarray
    rigid_body_modes: int
    modal_mass: np.ndarray
    modal_stiffness: np.ndarray
    orthogonality_mass: np.ndarray
    orthogonality_stiffness: np.ndarray
    boundary_unknowns: np.ndarray
    unknown_labels: tuple[str, ...]
    port_states: dict[str, np.ndarray]
    point_displacements: dict[str, np.ndarray]
    com_displacements: dict[str, np.ndarray]
    beam_fields: dict[str, BeamField]
    normalization: str
    note: str = ""

    @property
    def frequencies_hz(self) -> np.ndarray:
        """(n,) natural frequencies, Hz."""
        return self.omega / (2 * np.pi)

    @property
    def mass_orthogonality_error(self) -> float:
        """Largest |off-diagonal| of ``orthogonality_mass``."""
        return float(np.max(np.abs(self.orthogonality_mass - np.eye(self.omega.size)), initial=0.0))

    @property
    def stiffness_orthogonality_error(self) -> float:
        """Largest |⟨K V^k, V^p⟩| / (√(M_k M_p) max(ω_k, ω_p)²) over k ≠ p.

        Pairs of two rigid-body modes are measured against the largest ω² instead.
        """
        squares = self.omega**2
        scale = np.maximum.outer(squares, squares)
        scale[scale == 0] = max(squares.max(initial=0.0), 1.0)
        off = self.orthogonality_stiffness - np.diag(np.diag(self.orthogonality_stiffness))
        return float(np.max(np.abs(off) / scale, initial=0.0))

    @property
    def energy_error(self) -> float:
        """Largest |K_k(strain energy) / (ω_k² M_k) − 1| over elastic modes (Rayleigh check)."""
        elastic = self.omega > 0
        diagonal = np.diag(self.orthogonality_stiffness)[elastic]
        return float(np.max(np.abs(diagonal / self.omega[elastic] ** 2 - 1), initial=0.0))

    def shape_matrix(self, points=None) -> np.ndarray:
        """The point displacements of every mode as one matrix.

        Parameters
        ----------
        points : sequence of str, optional
            The p points, in the order wanted (default: every point).

        Returns
        -------
        numpy.ndarray, shape (n, 6 p)
            x, y, z, rx, ry, rz of each point in turn, per mode.
        """
        names = list(self.point_displacements) if points is None else list(points)
        return np.concatenate([self.point_displacements[p] for p in names], axis=1)

    def mac(self, other_shapes, points=None) -> np.ndarray:
        """MAC matrix between these modes and other shapes at the same points.

        Parameters
        ----------
        other_shapes : array_like, shape (n_other, 6 p)
            Shapes laid out as :meth:`shape_matrix` lays them out.
        points : sequence of str, optional
            The p points (default: every point).

        Returns
        -------
        numpy.ndarray, shape (n, n_other)
            In [0, 1] (:func:`mac_matrix`).
        """
        return mac_matrix(self.shape_matrix(points), other_shapes)

    def to_dict(self) -> dict:
        """Plain JSON-ready dictionary (lists of floats).

        Returns
        -------
        dict
            ``model``, ``frequencies_hz``, ``omega``, ``rigid_body_modes``, ``normalization``,
            the modal masses and stiffnesses, orthogonality errors and matrices, and the
            displacements by point, mass centre and beam field.
        """
        return {
            "model": self.model,
            "frequencies_hz": self.frequencies_hz.tolist(),
            "omega": self.omega.tolist(),
            "rigid_body_modes": self.rigid_body_modes,
            "normalization": self.normalization,
            **({"note": self.note} if self.note else {}),
            "modal_mass": self.modal_mass.tolist(),
            "modal_stiffness": self.modal_stiffness.tolist(),
            "mass_orthogonality_error": self.mass_orthogonality_error,
            "stiffness_orthogonality_error": self.stiffness_orthogonality_error,
            "orthogonality_mass": self.orthogonality_mass.tolist(),
            "orthogonality_stiffness": self.orthogonality_stiffness.tolist(),
            "point_displacements": {p: d.tolist() for p, d in self.point_displacements.items()},
            "com_displacements": {b: d.tolist() for b, d in self.com_displacements.items()},
            "beam_fields": {b: {"stations": f.stations.tolist(), "positions": f.positions.tolist(),
                                "displacements": f.displacements.tolist()}
                            for b, f in self.beam_fields.items()},
        }


def mac_matrix(a, b) -> np.ndarray:
    """Modal assurance criterion between two sets of shape vectors.

    Parameters
    ----------
    a : array_like, shape (n_a, d)
        Shapes, real or complex.
    b : array_like, shape (n_b, d)
        Shapes, real or complex.

    Returns
    -------
    numpy.ndarray, shape (n_a, n_b)
        |a_i · conj(b_j)|² / ((a_i · conj(a_i)) (b_j · conj(b_j))), in [0, 1].
    """
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    cross = np.abs(a @ b.conj().T) ** 2
    return cross / np.outer(np.sum(np.abs(a) ** 2, axis=1), np.sum(np.abs(b) ** 2, axis=1))


@single_blas_thread
def mode_shapes(model: Model, count: int | None = 10, *, fmax: float | None = None,
                stations: int = 21, normalization: str = DEFAULT_NORMALIZATION, rigid_body: bool = True,
                root: str | None = None, guess_hz=None, engine: str = "auto") -> ModalResult:
    """Natural modes of ``model`` by the transfer matrix method.

    The frequencies come from the pipeline of
    :func:`linmstmm.solve.natural_frequencies` (:func:`linmstmm.solve.solve_roots`:
    the same deduction, root finder and mpmath refinement), so they agree
    with it to the last digit.

    Parameters
    ----------
    model : Model
        The model.
    count : int or None
        The lowest ``count`` elastic modes. A repeated frequency always comes
        with its whole eigenspace, so one more mode than ``count`` may come back.
    fmax : float or None
        Hz: all modes up to fmax (with ``count``: whichever stops first);
        ``fmax`` alone is checked as :func:`linmstmm.solve.natural_frequencies` checks it.
    stations : int
        Number of equally spaced stations (ends included) of each beam field.
    normalization : str
        "mass" (the default, also of ``linmstmm modes``: M_k = 1 kg,
        amplitudes in m/√kg and rad/√kg) or "max" (largest translation 1 m; a
        mode without translation: largest rotation 1 rad). The largest
        component is made positive either way.
    rigid_body : bool
        Include the zero-frequency modes first.
    root : str or None
        Boundary end to use as the root of the transfer tree.
    guess_hz : array_like or None
        Frequencies (Hz) of a similar model (a neighbouring step of a sweep)
        to start the root search from, as for
        :func:`linmstmm.solve.natural_frequencies` (with ``count`` only).
    engine : str
        How the root search evaluates det Ū_all, as for
        :func:`linmstmm.solve.natural_frequencies` ("auto", "numpy" or "compiled");
        with the same engine the frequencies are that function's to the last
        digit, across engines they agree to rounding.

    Returns
    -------
    ModalResult

    Raises
    ------
    ModelError
        For a range holding too many modes, or no mode at all (key ``fmax``).
    """
    if normalization not in NORMALIZATIONS:
        raise ValueError(f"normalization must be one of {NORMALIZATIONS}, got {normalization!r}")
    if stations < 2:
        raise ValueError(f"stations must be >= 2, got {stations}")
    solution = solve_roots(model, count, fmax, root=root, guess_hz=guess_hz, engine=engine)
    deduction, finder = solution.deduction, solution.finder
    omegas = solution.omegas
    if count and omegas.size == count:  # the count may cut the last eigenspace
        omegas = _whole_last_eigenspace(finder, omegas)
    eigenspaces = _group(omegas)
    elastic = sum(m for _, m in eigenspaces)
    kept = {w for w, _ in eigenspaces}
    note = search_note(finder, elastic, {w: v for w, v in solution.unseparated.items() if w in kept}, count, fmax)
    if rigid_body and (rigid := finder.rigid_body_modes()):
        eigenspaces.insert(0, (0.0, rigid))
    if not eigenspaces:
        raise ModelError(model.source or model.name, "no mode to compute: " + (
            f"no natural frequency up to {fmax:g} Hz" if count is None else "the model has no mode"),
            key="fmax" if count is None else None)
    omega = np.repeat([w for w, _ in eigenspaces], [m for _, m in eigenspaces])
    report("mode shapes")
    zbar = np.concatenate([_null_basis(deduction, w, m) for w, m in eigenspaces])
    raw = _Fields.of(model, deduction, omega, zbar, stations)
    gram = raw.mass_gram()
    transform = _mass_orthonormal(gram, raw.mass_gram(_AXIS_WEIGHTS), [m for _, m in eigenspaces])
    transform = transform * _normalisation(raw.apply(transform), normalization, model)
    fields = raw.apply(transform)
    mass = transform.T @ gram @ transform
    stiffness = transform.T @ raw.stiffness_gram() @ transform
    modal_mass = np.diag(mass).copy()
    norm = np.sqrt(np.outer(modal_mass, modal_mass))
    note = "; ".join(part for part in (note, _accuracy_note(omega, mass / norm, stiffness / norm)) if part)
    return ModalResult(
        model.name, omega, int(np.sum(omega == 0)), modal_mass, omega**2 * modal_mass,
        mass / norm, stiffness / norm, fields.zbar, tuple(deduction.columns), fields.port_states,
        fields.point_displacements, fields.com_displacements,
        {beam.name: BeamField(raw.stations[beam.name], _station_positions(model, beam, raw),
                              fields.station_states[beam.name][..., :6])
         for beam in model.beams},
        normalization, note)


def _accuracy_note(omega: np.ndarray, mass: np.ndarray, stiffness: np.ndarray) -> str:
    """What the result must say about shapes off by more than SHAPE_ACCURACY ("" if none).

    omega : (n,) rad/s, ascending; mass, stiffness : (n, n) normalised orthogonality
    matrices (unit diagonal of ``mass``). A mode is off where its column of ``mass``
    above the diagonal has an entry (a pair blames its higher mode), or its Rayleigh
    quotient K_kk / (ω_k² M_kk) differs from 1, by more than SHAPE_ACCURACY.
    """
    off = np.triu(np.abs(mass - np.eye(omega.size)), 1).max(axis=0, initial=0.0)
    elastic = omega > 0
    rayleigh = np.zeros(omega.size)
    rayleigh[elastic] = np.abs(np.diag(stiffness)[elastic] / omega[elastic] ** 2 - 1)
    bad = np.flatnonzero(np.maximum(off, rayleigh) > SHAPE_ACCURACY)
    if not bad.size:
        return ""
    k = bad[0]
    return (f"the mode shapes from {omega[k] / (2 * np.pi):.6g} Hz up are not accurate in float64 (mode {k + 1}: "
            f"mass orthogonality off by {off[k]:.1e}, Rayleigh quotient by {rayleigh[k]:.1e}; "
            f"worst {np.max(np.maximum(off, rayleigh)):.1e})")


# --- eigenspaces ------------------------------------------------------------

def _group(omegas) -> list[tuple[float, int]]:
    """(ω, multiplicity) from an ascending list that repeats each root per multiplicity."""
    groups: list[tuple[float, int]] = []
    for omega in omegas:
        if groups and abs(omega - groups[-1][0]) <= SAME_FREQUENCY * omega:
            groups[-1] = (groups[-1][0], groups[-1][1] + 1)
        else:
            groups.append((float(omega), 1))
    return groups


def _whole_last_eigenspace(finder, omegas: np.ndarray) -> np.ndarray:
    """``omegas`` (rad/s, ascending) with the last root repeated up to its multiplicity.

    The multiplicity is the finder's count of roots around it
    (:meth:`~linmstmm.roots.RootFinder.multiplicity`), as the mpmath
    refinement of a root cut by the count takes it; the roots before it are
    left exactly as found.
    """
    last = omegas[-1]
    present = int(np.count_nonzero(np.abs(omegas - last) <= SAME_FREQUENCY * last))
    wanted = finder.multiplicity(last, sorted(set(omegas))) or present
    return np.r_[omegas, np.full(max(wanted - present, 0), last)]


def _null_basis(deduction: Deduction, omega: float, dimension: int) -> np.ndarray:
    """(dimension, N) basis of the null space of Ū_all(omega), on all N unknowns.

    Works on the equilibrated matrix S = ``rows · Ū · cols`` (the basis is
    mapped back by ``cols``), whose scales come from Ū at ω(1 ± SCALE_PROBE):
    at the root itself an entry that vanishes there (cos kL of a rod at
    resonance) would be blown up to ~1 when alone in its row, hiding the
    singularity. The SVD of S gives the left and right singular vectors u, v
    of the ``dimension`` smallest singular values; the basis then solves the
    bordered system [[S, u], [vᵀ, 0]] [x; λ] = [0; I]. The SVD alone mixes all
    columns with errors eps ‖S‖ / σ_next, and σ_next is as small as
    1/cosh(βL) for a beam; elimination keeps blocks that do not couple
    (bending, torsion) exactly apart. Released (statically indeterminate)
    unknowns are zero. Raises RuntimeError if any of the ``dimension``
    singular values is not below NULL_TOLERANCE × the largest.
    """
    matrix, below, above = deduction.matrix(omega * np.array([1.0, 1 - SCALE_PROBE, 1 + SCALE_PROBE]))
    rows, cols = equilibration(np.maximum(np.abs(below), np.abs(above)))
    scaled = rows[:, None] * matrix * cols
    u, sigma, vh = np.linalg.svd(scaled)
    worst = sigma[sigma.size - dimension] / sigma[0]
    if worst > NULL_TOLERANCE:
        raise RuntimeError(f"ω = {omega:.12g} rad/s is not a natural frequency with a null space "
                           f"of dimension {dimension}: relative singular value {worst:.3g}")
    n = sigma.size
    try:
        basis = _bordered_null_vectors(scaled, u, vh, dimension)
    except np.linalg.LinAlgError:  # other near-null directions than the root's: all of them, then the root's
        near = int(np.sum(sigma < NULL_TOLERANCE * sigma[0]))
        basis = _closest_null_vectors(_bordered_null_vectors(scaled, u, vh, near), u[:, n - near:], scaled,
                                      rows[:, None] * (above - below) * cols, dimension)
    full = np.zeros((dimension, deduction.full_order))
    full[:, np.delete(np.arange(n + len(deduction.released_columns)), deduction.released_columns)] = (
        np.linalg.qr(basis)[0].T * cols)
    return full


def _bordered_null_vectors(scaled: np.ndarray, u: np.ndarray, vh: np.ndarray, k: int) -> np.ndarray:
    """(N, k) null vectors of ``scaled`` (N, N) from the bordered system [[S, u], [vᵀ, 0]]
    on its last ``k`` left and right singular vectors (``u``, ``vh`` of its SVD).
    Raises LinAlgError where that system is singular."""
    n = scaled.shape[0]
    bordered = np.block([[scaled, u[:, n - k:]], [vh[n - k:], np.zeros((k, k))]])
    return np.linalg.solve(bordered, np.eye(n + k, k, -n))[:n]


def _closest_null_vectors(candidates: np.ndarray, left: np.ndarray, scaled: np.ndarray,
                          change: np.ndarray, dimension: int) -> np.ndarray:
    """(N, dimension): the combinations of ``candidates`` (N, k), k > dimension near-null
    vectors of the equilibrated Ū_all ``scaled`` (N, N), that belong to the root itself.

    Far above a beam's first modes the blocks of Ū_all of its other deformations are
    nearly singular too (a bending block's smallest singular value is about 1/cosh βL
    of its largest), below NULL_TOLERANCE, so the SVD offers their directions with
    the root's own. Newton's offsets tell them apart: on the candidates (projected on
    the near-null left vectors ``left`` (N, k)), the generalized eigenvalues μ of
    (Ū_all, ``change``) are the steps to the nearest root along each (``change``: the
    equilibrated Ū_all(ω(1 + p)) − Ū_all(ω(1 − p)), proportional to dŪ/dω). The
    root's own have μ ≈ 0; a nearly singular block's μ is the distance to its own
    root, or infinite. The ``dimension`` smallest are taken.
    """
    pencil = left.conj().T @ scaled @ candidates, left.conj().T @ change @ candidates
    mu, vectors = scipy.linalg.eig(*pencil)
    mu = np.where(np.isfinite(mu), np.abs(mu), np.inf)
    chosen = vectors[:, np.argsort(mu)[:dimension]]
    # (a real pencil's eigenvectors of real μ are real: LAPACK's, packed as complex)
    return candidates @ (chosen.real if np.isrealobj(scaled) else chosen)


def _mass_orthonormal(gram: np.ndarray, directional: np.ndarray, sizes) -> np.ndarray:
    """(n, n) block-diagonal combinations of the raw modes, mass-orthonormal per eigenspace.

    sizes : dimension of each eigenspace, in order. Each block's basis is made
    mass-orthonormal by the eigen-decomposition of its mass matrix, then turned
    to diagonalise ``directional`` (the translational kinetic energy weighted
    1, 2, 3 along x, y, z), so that a symmetric structure gets modes along the
    axes.
    """
    transform = np.zeros_like(gram)
    start = 0
    for size in sizes:
        block = slice(start, start + size)
        values, vectors = np.linalg.eigh(gram[block, block])
        basis = vectors / np.sqrt(values)
        transform[block, block] = basis @ np.linalg.eigh(basis.T @ directional[block, block] @ basis)[1]
        start += size
    return transform


def _normalisation(fields, normalization: str, model: Model) -> np.ndarray:
    """(n,) factors turning mass-orthonormal modes into ``normalization``, largest component > 0."""
    samples = fields.displacement_samples()  # (n, s, 6)
    translation = samples[..., :3].reshape(samples.shape[0], -1)
    rotation = samples[..., 3:].reshape(samples.shape[0], -1)
    coords = np.array(list(model.points.values()))
    size = max(np.ptp(coords, axis=0).max(), 1.0)
    moves = (np.abs(translation).max(axis=1)
             > _TRANSLATION_FLOOR * size * np.abs(rotation).max(axis=1))
    reference = np.where(moves[:, None], translation, rotation)
    largest = reference[np.arange(reference.shape[0]), np.abs(reference).argmax(axis=1)]
    return 1 / largest if normalization == "max" else np.sign(largest)


# --- states and fields ------------------------------------------------------

@dataclass(frozen=True, eq=False)
class _Fields:
    """Everything linear in z̄ for a set of modes; ``apply`` recombines modes.

    element_states : per transfer element (n, ports, 12), topology convention.
    station_states, quadrature_states : beam -> (n, s, 12), traversal convention.
    """

    names: tuple
    points: tuple
    element_states: list
    station_states: dict
    quadrature_states: dict
    zbar: np.ndarray
    topology: object
    stations: dict
    quadrature: dict

    @classmethod
    def of(cls, model, deduction, omega, zbar, n_stations):
        topology = deduction.topology
        states = _element_states(deduction, omega, zbar)
        index = {el.name: e for e, el in enumerate(topology.elements)}
        stations, quadrature, at_stations, at_nodes = {}, {}, {}, {}
        for beam in model.beams:
            e = index[beam.name]
            stations[beam.name] = np.linspace(0.0, beam.length, n_stations)
            quadrature[beam.name] = _quadrature(beam, omega.max(initial=0.0))
            at_stations[beam.name] = _beam_states(beam, topology.elements[e], omega, states[e],
                                                  stations[beam.name])
            at_nodes[beam.name] = _beam_states(beam, topology.elements[e], omega, states[e],
                                               quadrature[beam.name][0])
        return cls(tuple(index), tuple(model.points), states, at_stations, at_nodes, zbar, topology, stations, quadrature)

    def apply(self, transform: np.ndarray) -> _Fields:
        """The fields of the modes ``transform.T @ raw modes`` (transform (n_raw, n))."""
        def combine(array):
            return np.einsum("rk,r...->k...", transform, array)
        return _Fields(self.names, self.points, [combine(s) for s in self.element_states],
                       {b: combine(s) for b, s in self.station_states.items()},
                       {b: combine(s) for b, s in self.quadrature_states.items()},
                       combine(self.zbar), self.topology, self.stations, self.quadrature)

    # -- by point and by body -------------------------------------------------
    @property
    def port_states(self) -> dict[str, np.ndarray]:
        return {f"{element.name}@{port.point}": self.element_states[e][:, p]
                for e, element in enumerate(self.topology.elements)
                for p, port in enumerate(element.ports)}

    @property
    def point_displacements(self) -> dict[str, np.ndarray]:
        """model point -> (n, 6), from the first port found at the point, in model order."""
        found = {}
        for e, element in enumerate(self.topology.elements):
            for p, port in enumerate(element.ports):
                found.setdefault(port.point, self.element_states[e][:, p, :6])
        return {point: found[point] for point in self.points}

    @property
    def com_displacements(self) -> dict[str, np.ndarray]:
        """rigid body -> (n, 6) translation and rotation of its mass centre."""
        return {el.name: self._com(el.record) for el in self.topology.elements if el.kind == "rigid"}

    def displacement_samples(self) -> np.ndarray:
        """(n, s, 6) displacements at every point and beam quadrature node."""
        at_points = np.stack(list(self.point_displacements.values()), axis=1)
        at_nodes = [s[..., :6] for s in self.quadrature_states.values()]
        return np.concatenate([at_points, *at_nodes], axis=1)

    # -- the body operators ---------------------------------------------------
    def mass_gram(self, axis_weights=np.ones(3)) -> np.ndarray:
        """(n, n) ⟨M V^k, V^p⟩; ``axis_weights`` (3,) scale the translational mass along x, y, z."""
        return _gram(self._mass_measures(np.asarray(axis_weights, float)))

    def stiffness_gram(self) -> np.ndarray:
        """(n, n) ⟨K V^k, V^p⟩ from the strain energy of springs and beams."""
        return _gram(self._stiffness_measures())

    def _mass_measures(self, axis_weights):
        for element in self.topology.elements:
            if element.kind != "rigid":
                continue
            rigid = element.record
            com = self._com(rigid)
            principal, axes = np.linalg.eigh(np.asarray(rigid.inertia, float))
            yield com[:, :3], rigid.mass * axis_weights
            yield com[:, 3:] @ axes, principal
        for beam, (nodes, weights) in self._beams():
            states = self.quadrature_states[beam.name]
            yield (states[..., :3].reshape(len(states), -1),
                   np.outer(beam.rho * beam.A * weights, axis_weights).ravel())
            torsion = states[..., 3:6] @ np.asarray(beam.axes, float)[0]
            yield torsion, beam.rho * beam.Ip * weights

    def _stiffness_measures(self):
        for e, element in enumerate(self.topology.elements):
            if element.kind != "spring":
                continue
            spring = element.record
            ends = [next(p for p, port in enumerate(element.ports) if port.point == end)
                    for end in spring.ends]
            delta = self.element_states[e][:, ends[1], :6] - self.element_states[e][:, ends[0], :6]
            axes = np.asarray(spring.axes, float)
            local = np.concatenate([delta[:, :3] @ axes.T, delta[:, 3:] @ axes.T], axis=1)
            finite = np.isfinite(spring.k)
            yield local[:, finite], np.asarray(spring.k, float)[finite]
        for beam, (nodes, weights) in self._beams():
            states = self.quadrature_states[beam.name]
            axes = np.asarray(beam.axes, float)
            moment = states[..., 6:9] @ axes.T  # local mx, my, mz
            force = states[..., 9:12] @ axes.T
            terms = [(moment[..., 1], beam.E * beam.Iy), (moment[..., 2], beam.E * beam.Iz)]
            if beam.axial:
                terms.append((force[..., 0], beam.E * beam.A))
            if beam.torsion:
                terms.append((moment[..., 0], beam.G * beam.J))
            for values, rigidity in terms:
                yield values, weights / rigidity

    def _com(self, rigid) -> np.ndarray:
        """(n, 6) mass-centre displacement u_c = u_p + θ × (c − p) from the body's first port."""
        e = self.names.index(rigid.name)
        element = self.topology.elements[e]
        port = self.element_states[e][:, 0]
        arm = np.asarray(rigid.com, float) - np.asarray(element.ports[0].position, float)
        return np.concatenate([port[:, :3] + np.cross(port[:, 3:6], arm), port[:, 3:6]], axis=1)

    def _beams(self):
        for element in self.topology.elements:
            if element.kind == "beam":
                yield element.record, self.quadrature[element.name]


def _gram(measures) -> np.ndarray:
    """Σ X diag(w) Xᵀ over the (X (n, d), w (d,)) measures."""
    return sum(np.einsum("kd,pd,d->kp", X, X, w) for X, w in measures)


def _element_states(deduction: Deduction, omega: np.ndarray, zbar: np.ndarray) -> list:
    """Per transfer element, (n, ports, 12): the state at each of its ports.

    Output ports come from ``Deduction.port_states``; an input port is linked
    to the output of its upstream element or to a tip (boundary or cut side).
    """
    outputs, _ = deduction.port_states(omega)
    n = omega.size

    def evaluate(state):
        return np.einsum("nik,nk->ni", state.matrix, zbar[:, state.columns])

    states = []
    for e, element in enumerate(deduction.topology.elements):
        ports = []
        for p, port in enumerate(element.ports):
            if p == element.output:
                ports.append(evaluate(outputs[e]))
            elif port.link[0] == "element":
                ports.append(evaluate(outputs[port.link[1]]))
            else:
                ports.append(evaluate(deduction.tip_state(port.link, n)))
        states.append(np.stack(ports, axis=1))
    return states


def _beam_states(beam, element, omega, port_states, stations) -> np.ndarray:
    """(n, s, 12) states at ``stations`` (m from ends[0]) by transfer from the input end.

    States are in the traversal convention of the topology (forces: what the
    part nearer the input exerts on the part beyond).
    """
    reverse = element.inputs[0] == 1
    z_in = port_states[:, element.inputs[0]]
    distances = beam.length - stations if reverse else stations
    out = np.empty((omega.size, stations.size, 12))
    for s, distance in enumerate(distances):
        if distance > 0:
            out[:, s] = np.einsum("nij,nj->ni", beam_transfer(beam, omega, reverse=reverse,
                                                              length=distance), z_in)
        else:
            out[:, s] = z_in
    return out


def _quadrature(beam, omega_max: float):
    """Gauss–Legendre (nodes (q,), weights (q,)) on [0, L], enough for the highest mode.

    q = (largest wavenumber at omega_max) × L + EXTRA_QUADRATURE_POINTS, where
    the wavenumbers are bending (ρAω²/EI)^¼, axial ω√(ρ/E), torsion ω√(ρIp/GJ).
    """
    count = int(np.ceil(max(beam.wavenumbers(omega_max).values()) * beam.length)) + EXTRA_QUADRATURE_POINTS
    nodes, weights = np.polynomial.legendre.leggauss(count)
    half = beam.length / 2
    return half * (nodes + 1), half * weights


def _station_positions(model: Model, beam, fields: _Fields) -> np.ndarray:
    """(s, 3) positions of a beam's stations, m."""
    start = np.asarray(model.points[beam.ends[0]], float)
    return start + fields.stations[beam.name][:, None] * np.asarray(beam.axes, float)[0]
