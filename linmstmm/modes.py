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

The null spaces are :mod:`linmstmm.eigenspaces`; the states, beam fields and
the two inner products of a set of modes are :mod:`linmstmm.mode_fields`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.eigenspaces import _group, _whole_last_eigenspace, null_bases
from linmstmm.mode_fields import _Fields, _station_positions
from linmstmm.model import Model, ModelError
from linmstmm.results import Result, decode_array, decode_arrays, encode_array
from linmstmm.solve import UNRECORDED_ENGINE, search_note, solve_roots
from linmstmm.stages import report
from linmstmm.threads import single_blas_thread

#: Normalisations of the modes: unit modal mass, or unit largest translation.
NORMALIZATIONS = ("mass", "max")
#: The one default, of :func:`mode_shapes` and of ``linmstmm modes``: unit modal mass.
DEFAULT_NORMALIZATION = "mass"
#: Mode shapes whose mass orthogonality or Rayleigh quotient is off by more than this
#: (relative) are named in the result's note (a free beam's 30th mode, βL = 36, was
#: off by 1e-2 and its 60th by 100 %, without a word).
SHAPE_ACCURACY = 1e-4
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
class ModalResult(Result):
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
    without_translation : (n,) bool, the modes without translation (a pure
        rotation); with "max" they are scaled to a largest rotation of 1 rad, so
        their modal mass is a moment of inertia (``modal_mass_units``).
    engine : "numpy" or "compiled": what evaluated det Ū_all and the Ū_all whose null
        spaces give the shapes ("auto" resolved; :data:`linmstmm.solve.UNRECORDED_ENGINE`
        for a result saved before results recorded it).
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
    without_translation: np.ndarray | None = None
    engine: str = "numpy"

    kind = "modes"

    @property
    def modal_mass_units(self) -> list[str]:
        """The unit of each modal mass.

        Returns
        -------
        list of str, length n
            "kg", or "kg m^2" for a mode scaled to a largest rotation of 1 rad
            ("max" normalisation of a mode without translation). Mass-normalised
            modes have M_k = 1 kg, their amplitudes per √kg.
        """
        return ["kg m^2" if by_rotation else "kg" for by_rotation in self._scaled_by_rotation()]

    @property
    def modal_stiffness_units(self) -> list[str]:
        """The unit of each modal stiffness (K_k = ω_k² M_k).

        Returns
        -------
        list of str, length n
            "N/m", or "N m/rad" where the modal mass is in kg m^2.
        """
        return ["N m/rad" if by_rotation else "N/m" for by_rotation in self._scaled_by_rotation()]

    def _scaled_by_rotation(self) -> np.ndarray:
        """(n,) bool: the modes whose scale is a rotation of 1 rad."""
        if self.normalization != "max" or self.without_translation is None:
            return np.zeros(self.omega.size, bool)
        return np.asarray(self.without_translation, bool)

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
            the modal masses and stiffnesses and their units per mode
            (``modal_mass_units``, ``modal_stiffness_units``), orthogonality errors and matrices, and the
            displacements by point, mass centre and beam field.
        """
        return {
            "model": self.model,
            "frequencies_hz": self.frequencies_hz.tolist(),
            "omega": self.omega.tolist(),
            "rigid_body_modes": self.rigid_body_modes,
            "normalization": self.normalization,
            "engine": self.engine,
            **({"note": self.note} if self.note else {}),
            "modal_mass": self.modal_mass.tolist(),
            "modal_stiffness": self.modal_stiffness.tolist(),
            "modal_mass_units": self.modal_mass_units,
            "modal_stiffness_units": self.modal_stiffness_units,
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

    def _restoring_dict(self) -> dict:
        """The augmented eigenvectors :meth:`to_dict` leaves out: z̄, its column labels and the port states."""
        return {"boundary_unknowns": encode_array(self.boundary_unknowns),
                "unknown_labels": list(self.unknown_labels),
                "port_states": {port: encode_array(states) for port, states in self.port_states.items()}}

    @classmethod
    def _from_data(cls, data: dict) -> ModalResult:
        """The result :meth:`~linmstmm.results.Result.to_record` describes."""
        fields = {name: BeamField(decode_array(f["stations"]), decode_array(f["positions"], ndim=2),
                                  decode_array(f["displacements"], ndim=3))
                  for name, f in data["beam_fields"].items()}
        return cls(data["model"], decode_array(data["omega"]), data["rigid_body_modes"],
                   decode_array(data["modal_mass"]), decode_array(data["modal_stiffness"]),
                   decode_array(data["orthogonality_mass"], ndim=2),
                   decode_array(data["orthogonality_stiffness"], ndim=2),
                   decode_array(data["boundary_unknowns"], ndim=2), tuple(data["unknown_labels"]),
                   decode_arrays(data["port_states"], ndim=2), decode_arrays(data["point_displacements"], ndim=2),
                   decode_arrays(data["com_displacements"], ndim=2), fields, data["normalization"],
                   data.get("note", ""),
                   np.array([unit == "kg m^2" for unit in data["modal_mass_units"]], bool)
                   if "modal_mass_units" in data else None, data.get("engine", UNRECORDED_ENGINE))

    def plot(self, model: Model, mode: int = 0):
        """One mode drawn over the undeformed ``model`` (:func:`linmstmm.plot.mode_shape_figure`).

        Three orthographic views and an isometric one, coloured by the size
        of the translation; the title gives the frequency, modal mass and
        drawing scale.

        Parameters
        ----------
        model : Model
            The model these modes are of (its points, bodies and springs).
        mode : int
            Index of the mode, from 0 (rigid-body modes first).

        Returns
        -------
        matplotlib.figure.Figure
            Not saved; matplotlib is imported on this call.
        """
        from linmstmm.plot import mode_shape_figure

        return mode_shape_figure(self, model, mode)


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
        digit, across engines they agree to rounding. The compiled engine also
        forms the Ū_all whose null spaces give the shapes
        (:func:`~linmstmm.eigenspaces.null_bases`), the same to rounding. The two
        engines' shapes differ as their roots' rounding makes them: by one to some
        tens of times the orthogonality errors on the test models (launcher 2's
        twelve lowest: 6.7e-9 where those errors are 4.7e-10), as they did when
        both engines' shapes came from the numpy carry.

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
    note = search_note(solution.search, elastic, {w: v for w, v in solution.unseparated.items() if w in kept},
                       count, fmax, solution.fallback)
    if rigid_body and (rigid := solution.search.rigid_body_modes):
        eigenspaces.insert(0, (0.0, rigid))
    if not eigenspaces:
        raise ModelError(model.source or model.name, "no mode to compute: " + (
            f"no natural frequency up to {fmax:g} Hz" if count is None else "the model has no mode"),
            key="fmax" if count is None else None)
    omega = np.repeat([w for w, _ in eigenspaces], [m for _, m in eigenspaces])
    report("mode shapes")
    zbar = null_bases(deduction, eigenspaces, finder.determinant.plain_matrix)
    raw = _Fields.of(model, deduction, omega, zbar, stations)
    gram = raw.mass_gram()
    transform = _mass_orthonormal(gram, raw.mass_gram(_AXIS_WEIGHTS), [m for _, m in eigenspaces])
    factors, without_translation = _normalisation(raw.apply(transform), normalization, model)
    transform = transform * factors
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
        normalization, note, without_translation, finder.determinant.engine)


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


def _normalisation(fields, normalization: str, model: Model) -> tuple[np.ndarray, np.ndarray]:
    """(n,) factors turning mass-orthonormal modes into ``normalization``, largest component > 0,
    and (n,) bool: the modes without translation (scaled by their rotation with "max")."""
    samples = fields.displacement_samples()  # (n, s, 6)
    translation = samples[..., :3].reshape(samples.shape[0], -1)
    rotation = samples[..., 3:].reshape(samples.shape[0], -1)
    coords = np.array(list(model.points.values()))
    size = max(np.ptp(coords, axis=0).max(), 1.0)
    moves = (np.abs(translation).max(axis=1)
             > _TRANSLATION_FLOOR * size * np.abs(rotation).max(axis=1))
    reference = np.where(moves[:, None], translation, rotation)
    largest = reference[np.arange(reference.shape[0]), np.abs(reference).argmax(axis=1)]
    return (1 / largest if normalization == "max" else np.sign(largest)), ~moves
