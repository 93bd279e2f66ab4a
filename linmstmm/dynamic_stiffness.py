"""The exact dynamic stiffness of Euler–Bernoulli beams, and how many natural
frequencies each beam has below ω with both ends clamped.

A beam's dynamic stiffness D(ω) maps the harmonic displacements of its two ends
to the forces that hold them, exactly (no mesh): for an axial or torsional rod
of stiffness EA (GJ), wavenumber k = ω √(ρA/EA) (ω √(ρI_p/GJ)) and length L,

    D = EA k / sin kL · [[cos kL, −1], [−1, cos kL]],

and for bending in one plane, over (v₁, θ₁, v₂, θ₂) with θ = v′, β⁴ = ρAω²/EI,
λ = βL, c, s = cos λ, sin λ, C, S = cosh λ, sinh λ and δ = 1 − cC:

    D = EI/δ · [[β³(cS + sC),  β²sS,        −β³(s + S),   β²(C − c)],
                [β²sS,         β(sC − cS),  −β²(C − c),   β(S − s)],
                [−β³(s + S),   −β²(C − c),  β³(cS + sC),  −β²sS],
                [β²(C − c),    β(S − s),    −β²sS,        β(sC − cS)]].

Its static part is the Hermite element's stiffness and its ω² term the
consistent mass (tests/test_dynamic_stiffness.py checks both). Evaluated stably
for every λ: below SERIES_BELOW every combination by its power series (δ
cancels to λ⁴/6), above it with numerator and denominator divided by cosh λ.

The clamped–clamped frequencies, where D has poles, are counted exactly
(Wittrick and Williams 1971): ⌊kL/π⌋ per rod, and per bending plane
i − (1 − (−1)^i sgn δ)/2 with i = ⌊λ/π⌋. These are the J₀ of the
Wittrick–Williams count (:mod:`linmstmm.wittrick_williams`).

Local DOFs per end ``(u, v, w, θx, θy, θz)`` as in :mod:`linmstmm.fe.elements`:
the x–y plane bends with EI_z over (v, θz), the x–z plane with EI_y over
(w, −θy). A direction a beam declares rigid (``axial`` or ``torsion`` False)
keeps only its inertia, the consistent mass, exact once the constraint that
both ends move alike is applied.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from linmstmm.model import Beam

#: Below this λ = βL the bending combinations are summed as power series (their
#: closed forms cancel: δ = 1 − cos λ cosh λ ≈ λ⁴/6).
SERIES_BELOW = 1.0
#: Terms of those series: the first left out is below 1e-30 of the first at λ = 1.
SERIES_TERMS = 8
#: A frequency closer than this (relative, in δ/cosh λ or sin kL) to a beam's
#: clamped–clamped one is a pole of D: the count there is left undecided.
POLE = 1e-10

_X_Y = np.array([1, 5, 7, 11])    # (v, θz) at both ends
_X_Z = np.array([2, 4, 8, 10])    # (w, θy) at both ends, θy = −w′
_FLIP = np.array([1.0, -1.0, 1.0, -1.0])
#: The bending block from its six distinct entries K11 = β³(cS + sC), K12 = β²sS,
#: β³(s + S), K14 = β²(C − c), K22 = β(sC − cS), K24 = β(S − s) (each over δ), with signs.
_BENDING_PATTERN = np.array([[0, 1, 2, 3], [1, 4, 3, 5], [2, 3, 0, 1], [3, 5, 1, 4]])
_BENDING_SIGNS = np.array([[1.0, 1.0, -1.0, 1.0], [1.0, 1.0, -1.0, 1.0],
                           [-1.0, -1.0, 1.0, -1.0], [1.0, 1.0, -1.0, 1.0]])
_AXIAL = np.array([0, 6])
_TORSION = np.array([3, 9])


@dataclass(frozen=True, eq=False)
class BeamTable:
    """The beams of a model as arrays, one entry per beam (n_beams,).

    EA, GJ : N, N m². EIy, EIz : N m². rhoA : kg/m. rhoIp : kg m. L : m.
    axial, torsion : bool, False where the beam is rigid in that direction.
    """

    EA: np.ndarray
    GJ: np.ndarray
    EIy: np.ndarray
    EIz: np.ndarray
    rhoA: np.ndarray
    rhoIp: np.ndarray
    L: np.ndarray
    axial: np.ndarray
    torsion: np.ndarray

    @classmethod
    def of(cls, beams: tuple[Beam, ...]) -> BeamTable:
        """The table of ``beams`` (records of :class:`linmstmm.model.Beam`)."""
        # one row per beam, read in one pass; each column the same products as one by one
        rows = np.array([(b.E * b.A, b.G * b.J, b.E * b.Iy, b.E * b.Iz, b.rho * b.A, b.rho * b.Ip, b.length,
                          b.axial, b.torsion) for b in beams], dtype=float).reshape(-1, 9)
        return cls(*rows[:, :7].T.copy(), axial=rows[:, 7] != 0, torsion=rows[:, 8] != 0)


def dynamic_stiffness(beams: BeamTable, omega: float) -> np.ndarray:
    """(n_beams, 12, 12) exact dynamic stiffness of each beam at ``omega`` (rad/s),
    in its local DOFs (N/m, N, N m/rad): :func:`dynamic_stiffnesses` at one frequency."""
    return dynamic_stiffnesses(beams, np.array([omega], dtype=float))[0]


def dynamic_stiffnesses(beams: BeamTable, omegas: np.ndarray) -> np.ndarray:
    """(m, n_beams, 12, 12) exact dynamic stiffness of each beam at each of the m
    ``omegas`` (rad/s), in its local DOFs (N/m, N, N m/rad), all formed at once.
    Infinite or NaN entries only at a clamped–clamped frequency (see
    :func:`clamped_counts`)."""
    omegas = np.asarray(omegas, dtype=float).ravel()
    n = beams.L.size
    every = BeamTable(*(np.tile(column, omegas.size) for column in dataclasses.astuple(beams)))
    omega = np.repeat(omegas, n)                  # frequency after frequency, each for every beam
    d = np.zeros((omega.size, 12, 12))
    _rod(d, _AXIAL, every.EA, every.rhoA, every.L, omega, every.axial)
    _rod(d, _TORSION, every.GJ, every.rhoIp, every.L, omega, every.torsion)
    d[:, _X_Y[:, None], _X_Y] = _bending(every.EIz, every.rhoA, every.L, omega)
    d[:, _X_Z[:, None], _X_Z] = _bending(every.EIy, every.rhoA, every.L, omega) * np.outer(_FLIP, _FLIP)
    return d.reshape(omegas.size, n, 12, 12)


def clamped_counts(beams: BeamTable, omega: float, at_least: bool = False) -> int | None:
    """J₀(ω): the natural frequencies of all beams with both ends clamped that lie
    below ``omega`` (rad/s), exactly; None within POLE of one of them. at_least:
    never None — a family float64 cannot place ω in (ω within POLE of one of its
    frequencies, or so high that POLE spans one) counts one fewer, a lower bound."""
    count = clamped_counts_at(beams, np.array([omega], dtype=float), at_least)[0]
    return None if count < 0 else int(count)


def clamped_counts_at(beams: BeamTable, omegas: np.ndarray, at_least: bool = False) -> np.ndarray:
    """(m,) float: :func:`clamped_counts` at each of the m ``omegas`` (rad/s), all formed
    at once, whole numbers (summed in float64, as one at a time: far above any frequency
    asked for they pass int64); −1 where it is None."""
    omegas = np.asarray(omegas, dtype=float).reshape(-1, 1)
    total = np.zeros(omegas.shape[0])
    unknown = np.zeros(omegas.shape[0], dtype=bool)
    for stiffness, inertia, deformable in ((beams.EA, beams.rhoA, beams.axial),
                                          (beams.GJ, beams.rhoIp, beams.torsion)):
        phase = omegas * beams.L[deformable] * np.sqrt(inertia / stiffness)[deformable] / math.pi
        nearest = np.round(phase)
        undecided = (nearest >= 1) & (np.abs(phase - nearest) < POLE * phase)
        unknown |= undecided.any(axis=1)
        total += np.maximum(np.floor(phase) - undecided, 0).sum(axis=1)
    for stiffness in (beams.EIy, beams.EIz):
        lam = beams.L * (beams.rhoA * omegas ** 2 / stiffness) ** 0.25
        considered = lam >= SERIES_BELOW            # none below 4.73
        delta = _hyperbolic(lam)[0] - np.cos(lam)   # (1 − cos λ cosh λ) / cosh λ
        undecided = considered & (np.abs(delta) < POLE)
        unknown |= undecided.any(axis=1)
        i = np.floor(lam / math.pi)
        exact = i - (1 - (-1.0) ** i * np.sign(delta)) / 2
        total += np.where(considered, np.maximum(np.where(undecided, i - 1, exact), 0), 0).sum(axis=1)
    return np.where(unknown & (not at_least), -1.0, total)


def _rod(d, dofs, stiffness, inertia, length, omega, deformable):
    """Write the rods' 2 × 2 blocks at ``dofs`` into ``d``: exact where deformable,
    the consistent mass alone where rigid."""
    k = omega * np.sqrt(inertia / stiffness)
    kl = k * length
    small = kl < 1e-8                             # the static limit, and massless rods
    safe = np.where(small, 1.0, kl)
    scale = np.where(small, stiffness / length, stiffness * k / np.sin(safe))
    diagonal = np.where(small, 1.0 - kl ** 2 / 3, np.cos(safe))
    off = np.where(small, -1.0 - kl ** 2 / 6, -1.0)
    rigid = -omega ** 2 * inertia * length / 6    # consistent mass: 2 on the diagonal, 1 off it
    diagonal = np.where(deformable, scale * diagonal, 2 * rigid)
    off = np.where(deformable, scale * off, rigid)
    d[:, dofs[0], dofs[0]] = d[:, dofs[1], dofs[1]] = diagonal
    d[:, dofs[0], dofs[1]] = d[:, dofs[1], dofs[0]] = off


def _bending(stiffness, inertia, length, omega):
    """(n, 4, 4) exact bending dynamic stiffness over (v₁, θ₁, v₂, θ₂), θ = v′."""
    beta = (inertia * omega ** 2 / stiffness) ** 0.25
    lam = beta * length
    series = lam < SERIES_BELOW
    combos = np.empty((lam.size, 7))
    combos[series], combos[~series] = _series(lam[series]), _scaled(lam[~series])
    delta, cs_sc, ss, s_plus, c_minus, sc_cs, s_minus = combos.T
    f = stiffness / delta
    # In the series each combination is divided by the power of λ that leads it,
    # so the powers of β become powers of 1/L (β^p λ^q / λ^4 = 1/L^p where q − 4 = −p).
    b1 = np.where(series, 1 / length, beta)
    b2 = np.where(series, 1 / length ** 2, beta ** 2)
    b3 = np.where(series, 1 / length ** 3, beta ** 3)
    entries = np.stack([f * b3 * cs_sc, f * b2 * ss, f * b3 * s_plus, f * b2 * c_minus,
                        f * b1 * sc_cs, f * b1 * s_minus], -1)
    return entries[:, _BENDING_PATTERN] * _BENDING_SIGNS


def _hyperbolic(lam):
    """(1 / cosh λ, tanh λ) from e^(−2λ): no overflow at any λ ≥ 0."""
    decay = np.exp(-2 * lam)
    return 2 * np.sqrt(decay) / (1 + decay), (1 - decay) / (1 + decay)


def _scaled(lam):
    """(n, 7) the combinations δ, cS + sC, sS, s + S, C − c, sC − cS, S − s, each
    divided by cosh λ (stable at any λ ≥ 0)."""
    c, s = np.cos(lam), np.sin(lam)
    inv_c, t = _hyperbolic(lam)
    return np.stack([inv_c - c, c * t + s, s * t, s * inv_c + t, 1.0 - c * inv_c, s - c * t, t - s * inv_c], -1)


def _series_coefficients() -> np.ndarray:
    """(SERIES_TERMS, 7): column i holds the coefficients of combination i of
    :func:`_scaled` in powers of λ⁴, divided by the power of λ that leads it:
    δ = −Σ_{j≥1} (−4)^j λ^{4j}/(4j)!, cS + sC = 2Σ (−4)^k λ^{4k+1}/(4k+1)!,
    sS = 2Σ (−4)^k λ^{4k+2}/(4k+2)!, s + S = 2Σ λ^{4k+1}/(4k+1)!,
    C − c = 2Σ λ^{4k+2}/(4k+2)!, sC − cS = 4Σ (−4)^k λ^{4k+3}/(4k+3)!,
    S − s = 2Σ λ^{4k+3}/(4k+3)!."""
    k = np.arange(SERIES_TERMS)
    alternating, plain = (-4.0) ** k, np.ones(SERIES_TERMS)
    columns = [(4, 4 * alternating), (1, 2 * alternating), (2, 2 * alternating), (1, 2 * plain),
               (2, 2 * plain), (3, 4 * alternating), (3, 2 * plain)]
    return np.column_stack([weights / np.array([math.factorial(4 * j + shift) for j in k], float)
                            for shift, weights in columns])


#: See :func:`_series_coefficients`; the compiled kernels use the same table.
SERIES_COEFFICIENTS = _series_coefficients()


def _series(lam):
    """(n, 7) the same combinations as :func:`_scaled`, by their power series, each
    divided by the power of λ that leads it (δ by λ⁴, cS + sC by λ, sS by λ², …),
    for λ below SERIES_BELOW. Their ratios are then the entries' coefficients in
    powers of 1/L (see :func:`_bending`)."""
    return (lam[:, None] ** 4) ** np.arange(SERIES_TERMS) @ SERIES_COEFFICIENTS
