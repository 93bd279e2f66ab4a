"""Natural frequencies of a model in mpmath, as roots of the determinant of its
dynamic stiffness D(λ) on the nodes of the FE route with one element per beam.

Each beam enters either exactly (the Euler–Bernoulli continuum: closed-form
dynamic stiffness of rods and bending, written here in mpmath), or as a chain
of ``n`` equal elements of the FE route (:func:`linmstmm.fe.beam_element`)
whose interior nodes are condensed exactly, by halving the chain ``log2 n``
times. The first is independent of both routes' arithmetic and of any mesh; the
second is the exact eigenproblem the FE route solves in float64 on that mesh.
Springs, rigid bodies, boundaries and constraints are those of
:func:`linmstmm.fe.assembly.constrained_parts`; no transfer matrix enters.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np

from linmstmm.fe import beam_element
from linmstmm.fe.assembly import constrained_parts
from linmstmm.fe.sparse import as_scipy
from linmstmm.wittrick_williams import _beam_maps

_AXIAL, _TORSION = (0, 6), (3, 9)
_X_Y, _X_Z = (1, 5, 7, 11), (2, 4, 8, 10)   # (v, θz) and (w, θy) at both ends, θy = −w′
_FLIP = (1, -1, 1, -1)


class ExactStiffness:
    """D(λ) of ``model`` (λ = ω², rad²/s²) in mpmath; ``elements`` None for exact
    beams, or a power of two: each beam a chain of that many FE elements."""

    def __init__(self, model, elements: int | None = None):
        parts = constrained_parts(model, 1)
        T = as_scipy(parts.T)
        springs = parts.spring_strains.matrix(parts.n_full) @ T
        stiffness = np.concatenate(parts.spring_stiffness) if parts.spring_stiffness else np.zeros(0)
        self.n = T.shape[1]
        self.static = mp.matrix((springs.T @ springs.multiply(stiffness[:, None])).toarray().tolist())
        self.mass = mp.matrix((T.T @ parts.rigid_mass.matrix(parts.n_full, parts.n_full) @ T).toarray().tolist())
        self.maps, self.columns = _beam_maps(parts, "numpy")
        self.beams, self.elements = model.beams, elements

    def __call__(self, lam) -> mp.matrix:
        """(n, n) D(λ) on the reduced DOFs."""
        matrix = self.static - lam * self.mass
        for beam, to_local, columns in zip(self.beams, self.maps, self.columns):
            local = _continuum(beam, mp.sqrt(lam)) if self.elements is None else _chain(beam, lam, self.elements)
            block = mp.matrix(to_local.T.tolist()) * local * mp.matrix(to_local.tolist())
            for a, row in enumerate(columns):
                for b, column in enumerate(columns):
                    if row < self.n and column < self.n:
                        matrix[int(row), int(column)] += block[a, b]
        return matrix

    def root(self, lam: float, digits: int = 50):
        """The root of det D nearest ``lam`` (a float64 guess), by secant steps in
        mpmath at ``digits`` until they change it by less than 1e-24 (relative);
        raises if det D does not change sign across it within 1e-18."""
        with mp.workdps(digits):
            def det(x):
                return mp.det(self(x))
            x0, x1 = mp.mpf(lam), mp.mpf(lam) * (1 + mp.mpf("1e-9"))
            f0, f1 = det(x0), det(x1)
            for _ in range(30):
                x0, x1, f0 = x1, x1 - f1 * (x1 - x0) / (f1 - f0), f1
                f1 = det(x1)
                if abs(x1 - x0) < mp.mpf("1e-24") * abs(x1):
                    break
            width = mp.mpf("1e-18") * x1
            if mp.sign(det(x1 - width)) == mp.sign(det(x1 + width)):
                raise ArithmeticError(f"det D keeps its sign across {x1}")
            return x1


def _rod(stiffness, inertia, length, omega):
    """(diagonal, off-diagonal) of an axial or torsional rod's exact dynamic stiffness."""
    k = omega * mp.sqrt(inertia / stiffness)
    scale = stiffness * k / mp.sin(k * length)
    return scale * mp.cos(k * length), -scale


def _bending(stiffness, inertia, length, omega):
    """(4, 4) exact bending dynamic stiffness over (v₁, θ₁, v₂, θ₂), θ = v′."""
    beta = (inertia * omega ** 2 / stiffness) ** mp.mpf(0.25)
    c, s = mp.cos(beta * length), mp.sin(beta * length)
    C, S = mp.cosh(beta * length), mp.sinh(beta * length)
    f = stiffness / (1 - c * C)
    k11, k12, k13 = f * beta ** 3 * (c * S + s * C), f * beta ** 2 * s * S, -f * beta ** 3 * (s + S)
    k14, k22, k24 = f * beta ** 2 * (C - c), f * beta * (s * C - c * S), f * beta * (S - s)
    return [[k11, k12, k13, k14], [k12, k22, -k14, k24], [k13, -k14, k11, -k12], [k14, k24, -k12, k22]]


def _continuum(beam, omega) -> mp.matrix:
    """(12, 12) exact dynamic stiffness of ``beam`` in its local DOFs."""
    E, G, rho, A, Iy, Iz, J, Ip, L = (mp.mpf(float(v)) for v in (
        beam.E, beam.G, beam.rho, beam.A, beam.Iy, beam.Iz, beam.J, beam.Ip, beam.length))
    d = mp.zeros(12, 12)
    for (i, j), stiffness, inertia in ((_AXIAL, E * A, rho * A), (_TORSION, G * J, rho * Ip)):
        d[i, i], d[i, j] = _rod(stiffness, inertia, L, omega)
        d[j, j], d[j, i] = d[i, i], d[i, j]
    z_plane, y_plane = _bending(E * Iz, rho * A, L, omega), _bending(E * Iy, rho * A, L, omega)
    for a in range(4):
        for b in range(4):
            d[_X_Y[a], _X_Y[b]] = z_plane[a][b]
            d[_X_Z[a], _X_Z[b]] = y_plane[a][b] * _FLIP[a] * _FLIP[b]
    return d


def _chain(beam, lam, elements: int) -> mp.matrix:
    """(12, 12) K − λM of ``elements`` equal FE elements of ``beam`` in a row, interior
    nodes condensed: halved ``log2 elements`` times."""
    g, d, m, constraints = beam_element(beam, beam.length / elements)
    if len(constraints) or elements & (elements - 1):
        raise ValueError("chains of a power of two of deformable elements only")
    g, m = mp.matrix(g.tolist()), mp.matrix(m.tolist())
    chain = g.T * mp.diag([mp.mpf(float(v)) for v in d]) * g - lam * m
    while elements > 1:
        outer, coupling, inner = chain[0:6, 0:6], chain[0:6, 6:12], chain[6:12, 6:12]
        middle = mp.inverse(inner + outer)          # the node two equal chains share
        halves = (outer - coupling * middle * coupling.T, -coupling * middle * coupling,
                  inner - coupling.T * middle * coupling)
        chain = mp.zeros(12, 12)
        for i in range(6):
            for j in range(6):
                chain[i, j], chain[i, 6 + j], chain[6 + i, 6 + j] = (h[i, j] for h in halves)
                chain[6 + j, i] = halves[1][i, j]
        elements //= 2
    return chain
