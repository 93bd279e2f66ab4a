"""The frame element of a beam (strain operator, stiffnesses, consistent mass,
constraints) and the dispersion error of a uniform mesh of it."""
from __future__ import annotations

import numpy as np
import scipy.linalg as la

from linmstmm.model import Beam


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
    rows, d, m, strain = frame_elements((beam,), np.array([h], float))
    return rows[0][strain[0]], d[0][strain[0]], m[0], rows[0][~strain[0]]


def frame_elements(beams, h: np.ndarray):
    """The elements of many beams at once, each beam's six deformation rows in the
    order bending x-y (relative rotation, chord defect), bending x-z (the same),
    stretch, twist.

    Parameters
    ----------
    beams : sequence of b :class:`~linmstmm.model.Beam`.
    h : (b,) element length of each beam, m.

    Returns
    -------
    rows : (b, 6, 12) the deformations as rows on the element's local DOFs (m or rad).
    d : (b, 6) their stiffnesses (N m or N m/rad); those of rigid directions unused.
    m : (b, 12, 12) consistent masses, kg and kg m².
    strain : (b, 6) bool, True where a row is a strain, False where the beam declares
        the direction rigid (``axial`` or ``torsion`` False: the row is a constraint).
    """
    E, G, rho, A, Iy, Iz, J, Ip = np.array([(beam.E, beam.G, beam.rho, beam.A, beam.Iy, beam.Iz, beam.J, beam.Ip)
                                            for beam in beams], float).reshape(-1, 8).T
    rows = _ROWS + (1 / h)[:, None, None] * _ROWS_PER_LENGTH
    d = np.stack([E * Iz / h, 12 * E * Iz / h, E * Iy / h, 12 * E * Iy / h, E * A / h, G * J / h], axis=1)
    strain = np.ones((len(h), 6), bool)
    strain[:, 4:] = np.array([(beam.axial, beam.torsion) for beam in beams], bool).reshape(-1, 2)
    return rows, d, _frame_masses(rho * A, rho * Ip, h), strain


def _deformation_rows() -> tuple[np.ndarray, np.ndarray]:
    """(6, 12) the deformation rows of :func:`frame_elements` as a part that does not
    depend on the element length and (6, 12) one to divide by it (m)."""
    u1, v1, w1, tx1, ty1, tz1, u2, v2, w2, tx2, ty2, tz2 = np.eye(12)
    zero = np.zeros(12)
    fixed = np.array([tz2 - tz1, (tz1 + tz2) / 2, ty2 - ty1, (ty1 + ty2) / 2, u2 - u1, tx2 - tx1])
    per_length = np.array([zero, v1 - v2, zero, w2 - w1, zero, zero])
    return fixed, per_length


_ROWS, _ROWS_PER_LENGTH = _deformation_rows()
#: Cubic Hermite consistent mass (v, θz at both nodes) / (ρA h / 420): constant, h and h² parts.
_HERMITE = (np.array([[156.0, 0, 54, 0], [0, 0, 0, 0], [54, 0, 156, 0], [0, 0, 0, 0]]),
            np.array([[0.0, 22, 0, -13], [22, 0, 13, 0], [0, 13, 0, -22], [-13, 0, -22, 0]]),
            np.array([[0.0, 0, 0, 0], [0, 4, 0, -3], [0, 0, 0, 0], [0, -3, 0, 4]]))
_BAR = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0
_FLIP = np.outer([1.0, -1.0, 1.0, -1.0], [1.0, -1.0, 1.0, -1.0])    # (v, θz) -> (w, −θy)


def _frame_masses(rho_a: np.ndarray, rho_ip: np.ndarray, h: np.ndarray) -> np.ndarray:
    """(b, 12, 12) consistent masses of frame elements without rotary inertia.

    rho_a : (b,) mass per length, kg/m. rho_ip : (b,) polar inertia per length, kg m.
    h : (b,) element lengths, m.
    """
    m = np.zeros((len(h), 144))                                                   # flattened 12 × 12
    m[:, _AXIAL] = (rho_a * h)[:, None] * _BAR.ravel()
    m[:, _TORSION] = (rho_ip * h)[:, None] * _BAR.ravel()
    h = h[:, None]
    constant, linear, square = (part.ravel() for part in _HERMITE)
    hermite = rho_a[:, None] * h / 420.0 * (constant + linear * h + square * h * h)
    m[:, _BENDING_Y] = hermite
    m[:, _BENDING_Z] = hermite * _FLIP.ravel()
    return m.reshape(-1, 12, 12)


def _block_places(dofs: list[int]) -> np.ndarray:
    """The places in a flattened 12 × 12 matrix of the block on ``dofs`` (rows and columns), row-major."""
    dofs = np.asarray(dofs)
    return (12 * dofs[:, None] + dofs).ravel()


_AXIAL, _TORSION = _block_places([0, 6]), _block_places([3, 9])
_BENDING_Y, _BENDING_Z = _block_places([1, 5, 7, 11]), _block_places([2, 4, 8, 10])     # (v, θz), (w, θy)


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
