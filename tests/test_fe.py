"""The finite-element route against closed-form results.

Models are built directly as records (no TOML). Beam references come from
the roots of the Euler–Bernoulli characteristic equations (Blevins, "Formulas
for natural frequency and mode shape", table 8-1):
f = (βL)² / (2π L²) · sqrt(EI / ρA).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from linmstmm.fe import DENSE_LIMIT, assemble, beam_element, dispersion_error, fe_frequencies, fe_modes
from linmstmm.model import Beam, Model, Rigid, Spring
from linmstmm.solve import natural_frequencies
from random_models import random_model

COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")
FREE = ()
PINNED = ("x", "y", "z")
CLAMPED = COMPONENTS
INF = np.inf


# --------------------------------------------------------------------------
# Model builders

def mask(components) -> np.ndarray:
    """(6,) bool boundary mask fixing the named components."""
    return np.isin(COMPONENTS, components)


def local_axes(direction, y_hint=None) -> np.ndarray:
    """(3, 3) rows = local x, y, z (model-format rule for the default y)."""
    x = np.asarray(direction, float) / np.linalg.norm(direction)
    if y_hint is None:
        y_hint = np.cross([0.0, 0.0, 1.0], x)
        if np.linalg.norm(y_hint) < 1e-12:
            y_hint = np.array([0.0, 1.0, 0.0])
    y = np.asarray(y_hint, float) - x * (x @ np.asarray(y_hint, float))
    y /= np.linalg.norm(y)
    return np.array([x, y, np.cross(x, y)])


def make_beam(name, points, a, b, *, E=1.0, G=1.0, rho=1.0, A=1.0, Iy=1.0, Iz=1.0,
              J=1.0, Ip=None, axial=True, torsion=True, y_hint=None) -> Beam:
    """A Beam record from ``points[a]`` to ``points[b]``."""
    span = np.asarray(points[b], float) - np.asarray(points[a], float)
    return Beam(name=name, ends=(a, b), E=E, G=G, rho=rho, A=A, Iy=Iy, Iz=Iz, J=J,
                Ip=Iy + Iz if Ip is None else Ip, axes=local_axes(span, y_hint),
                length=float(np.linalg.norm(span)), axial=axial, torsion=torsion)


def make_body(name, ports, com, mass, inertia=(0.0, 0.0, 0.0)) -> Rigid:
    """A Rigid record; ``inertia`` diagonal (3,) or full (3, 3)."""
    inertia = np.asarray(inertia, float)
    return Rigid(name=name, ports=tuple(ports), mass=float(mass),
                 com=np.asarray(com, float),
                 inertia=np.diag(inertia) if inertia.ndim == 1 else inertia)


def make_spring(name, a, b, k, axes=None) -> Spring:
    """A Spring record; k (6,) N/m and N m/rad, axes rows = local x, y, z."""
    return Spring(name=name, ends=(a, b), k=np.asarray(k, float),
                  axes=np.eye(3) if axes is None else np.asarray(axes, float))


def single_beam(end_a, end_b, length=1.0, direction=(1.0, 0.0, 0.0), **properties) -> Model:
    """One beam of ``length`` along ``direction``; boundaries at both ends."""
    tip = length * np.asarray(direction, float) / np.linalg.norm(direction)
    points = {"a": np.zeros(3), "b": tip}
    return Model(name="beam", points=points,
                 beams=(make_beam("beam", points, "a", "b", **properties),),
                 boundary={p: mask(c) for p, c in (("a", end_a), ("b", end_b)) if c})


def spring_chain(masses, k, lateral=INF) -> Model:
    """1-D chain ground–k–m₁–k–m₂–…–k–ground along x.

    Body i sits at x = i with ports at x = i ± ½; each spring joins coinciding
    ports. ``lateral`` is the stiffness of all other spring directions
    (``inf`` = rigid), so only the x motions are elastic.
    """
    n = len(masses)
    points = {"ground0": np.array([0.5, 0.0, 0.0]), f"ground{n}": np.array([n + 0.5, 0.0, 0.0])}
    bodies, springs = [], []
    for i, m in enumerate(masses, start=1):
        points[f"left{i}"] = np.array([i - 0.5, 0.0, 0.0])
        points[f"right{i}"] = np.array([i + 0.5, 0.0, 0.0])
        bodies.append(make_body(f"mass{i}", [f"left{i}", f"right{i}"], [i, 0.0, 0.0], m))
    ends = ["ground0"] + [f"{side}{i}" for i in range(1, n + 1) for side in ("left", "right")]
    ends.append(f"ground{n}")
    stiffness = [k] + [lateral] * 5
    for j in range(n + 1):
        springs.append(make_spring(f"spring{j}", ends[2 * j], ends[2 * j + 1], stiffness))
    return Model(name="chain", points=points, rigids=tuple(bodies), springs=tuple(springs),
                 boundary={"ground0": mask(CLAMPED), f"ground{n}": mask(CLAMPED)})


# --------------------------------------------------------------------------
# Closed forms

#: Characteristic functions of βL (scaled to stay finite) and the offset c of
#: their asymptotic roots βL ≈ (n + c)π, n = 1, 2, ...
CHARACTERISTIC = {
    "clamped-free": (lambda x: np.cos(x) + 1.0 / np.cosh(x), -0.5),
    "clamped-clamped": (lambda x: np.cos(x) - 1.0 / np.cosh(x), 0.5),
    "clamped-pinned": (lambda x: np.tan(x) - np.tanh(x), 0.25),
    "pinned-pinned": (np.sin, 0.0),
}


def beta_l(kind: str, count: int) -> np.ndarray:
    """The first ``count`` roots βL (free-free = clamped-clamped), to ~1e-15."""
    function, offset = CHARACTERISTIC[kind]
    guesses = (np.arange(1, count + 1) + offset) * np.pi
    return np.array([brentq(function, g - 0.35, g + 0.35, xtol=1e-15, rtol=1e-15)
                     for g in guesses])


def bending_hz(kind, count, EI, rho_a=1.0, length=1.0) -> np.ndarray:
    """(count,) bending frequencies, Hz, of a uniform beam (EI N m², ρA kg/m, L m)."""
    return beta_l(kind, count) ** 2 / (2 * np.pi * length ** 2) * np.sqrt(EI / rho_a)


def hermite_stiffness(EI, length) -> np.ndarray:
    """(4, 4) Euler–Bernoulli stiffness on (w₁, w₁', w₂, w₂'), Przemieniecki (1968)."""
    h = length
    return EI / h ** 3 * np.array([[12, 6 * h, -12, 6 * h],
                                   [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                   [-12, -6 * h, 12, -6 * h],
                                   [6 * h, 2 * h * h, -6 * h, 4 * h * h]])


def relative_error(computed, exact) -> np.ndarray:
    """|computed / exact − 1|, elementwise."""
    return np.abs(np.asarray(computed) / np.asarray(exact) - 1.0)


def assert_honest(result, exact, tolerance):
    """Within ``tolerance`` of ``exact`` and within the tool's own error estimate
    (plus the ~1e-15 rounding of the reference itself)."""
    error = relative_error(result.frequencies_hz, exact)
    assert error.max() <= tolerance, error
    assert np.all(error <= result.error_estimate + 2e-15), (error, result.error_estimate)


# --------------------------------------------------------------------------
# Element

def test_beam_element_stiffness_is_the_textbook_frame_element():
    """Gᵀ diag(D) G equals the textbook 12x12 frame stiffness (Przemieniecki 1968)."""
    E, G, A, Iy, Iz, J, h = 2.0, 0.7, 0.3, 0.011, 0.023, 0.017, 0.9
    beam = make_beam("b", {"a": np.zeros(3), "b": np.array([h, 0, 0])}, "a", "b",
                     E=E, G=G, A=A, Iy=Iy, Iz=Iz, J=J)
    g, d, m, _ = beam_element(beam, h)
    K = np.zeros((12, 12))
    for (i, j), value in {(0, 0): E * A / h, (3, 3): G * J / h}.items():
        K[np.ix_([i, j + 6], [i, j + 6])] = value * np.array([[1, -1], [-1, 1]])
    for EI, (w, t), sign in ((E * Iz, (1, 5), 1), (E * Iy, (2, 4), -1)):
        dofs = [w, t, w + 6, t + 6]
        flip = np.diag([1, sign, 1, sign])                  # θy = −w'
        K[np.ix_(dofs, dofs)] = flip @ hermite_stiffness(EI, h) @ flip
    np.testing.assert_allclose(g.T @ np.diag(d) @ g, K, rtol=1e-13, atol=1e-13 * np.abs(K).max())
    assert np.allclose(m, m.T) and np.linalg.eigvalsh(m).min() > 0


# --------------------------------------------------------------------------
# Beams

#: (boundary at a, at b, characteristic, rigid-body modes); bending only.
BEAM_CASES = {
    "cantilever": (CLAMPED, FREE, "clamped-free", 0),
    "clamped-clamped": (CLAMPED, CLAMPED, "clamped-clamped", 0),
    "pinned-pinned": (PINNED, PINNED, "pinned-pinned", 1),     # spin about the axis
    "clamped-pinned": (CLAMPED, PINNED, "clamped-pinned", 0),
    "free-free": (FREE, FREE, "clamped-clamped", 6),
}


@pytest.mark.parametrize("case", BEAM_CASES)
def test_bending_in_both_planes(case):
    """Iy = 2.25 Iz: two families f and 1.5 f; axial and torsion rigid."""
    end_a, end_b, kind, rigid = BEAM_CASES[case]
    model = single_beam(end_a, end_b, length=2.0, E=3.0, rho=1.5, A=0.5, Iz=0.4, Iy=0.9,
                        axial=False, torsion=False)
    count = 8
    families = [bending_hz(kind, count, 3.0 * I, 1.5 * 0.5, 2.0) for I in (0.4, 0.9)]
    exact = np.sort(np.concatenate(families))[:count]
    result = fe_frequencies(model, count=count, rtol=1e-10)
    assert result.rigid_body_modes == rigid
    assert_honest(result, exact, 1e-8)


def test_rotated_beam_gives_the_same_frequencies():
    """A cantilever along (1, 2, 2)/3 with a skew y axis: the same frequencies."""
    properties = dict(E=3.0, Iz=0.4, Iy=0.9, axial=False, torsion=False)
    rotated = single_beam(CLAMPED, FREE, direction=(1.0, 2.0, 2.0), y_hint=(1.0, -1.0, 3.0),
                          **properties)
    exact = np.sort(np.concatenate([bending_hz("clamped-free", 6, 3.0 * I) for I in (0.4, 0.9)]))
    assert_honest(fe_frequencies(rotated, count=6), exact[:6], 1e-8)


def test_axial_rod_fixed_free():
    """ω = (2n−1)π/(2L) sqrt(E/ρ); bending pushed above by a huge I, no torsion."""
    model = single_beam(CLAMPED, FREE, length=2.0, E=5.0, rho=2.0, Iy=1e3, Iz=1e3,
                        torsion=False)
    n = np.arange(1, 5)
    exact = (2 * n - 1) * np.pi / (2 * 2.0) * np.sqrt(5.0 / 2.0) / (2 * np.pi)
    assert_honest(fe_frequencies(model, count=4), exact, 1e-8)


def test_torsional_shaft_fixed_free():
    """ω = (2n−1)π/(2L) sqrt(GJ/(ρ Ip)); axially rigid, bending pushed above."""
    model = single_beam(CLAMPED, FREE, length=2.0, G=3.0, J=0.5, rho=2.0, Ip=0.25,
                        Iy=1e3, Iz=1e3, axial=False)
    n = np.arange(1, 5)
    exact = (2 * n - 1) * np.pi / (2 * 2.0) * np.sqrt(3.0 * 0.5 / (2.0 * 0.25)) / (2 * np.pi)
    assert_honest(fe_frequencies(model, count=4), exact, 1e-8)


def test_cantilever_with_tip_mass_equal_to_beam_mass():
    """Tip mass μ = 1 (no rotary inertia): λ² = 1.557298, 16.25009, 50.89584.

    λ = βL solves 1 + cos λ cosh λ + μλ (cos λ sinh λ − sin λ cosh λ) = 0
    (Blevins table 8-8); ω = λ² sqrt(EI / (ρA L⁴)).
    """
    length, EI, rho_a = 1.5, 2.0, 0.8
    points = {"root": np.zeros(3), "tip": np.array([length, 0.0, 0.0])}
    model = Model(name="tip mass", points=points,
                  beams=(make_beam("arm", points, "root", "tip", E=EI, rho=rho_a, Iy=1.0, Iz=1.0,
                                   axial=False, torsion=False),),
                  rigids=(make_body("payload", ["tip"], points["tip"], rho_a * length),),
                  boundary={"root": mask(CLAMPED)})
    result = fe_frequencies(model, count=6)
    lam_squared = (2 * np.pi * result.frequencies_hz[::2]) / np.sqrt(EI / (rho_a * length ** 4))
    np.testing.assert_allclose(lam_squared, [1.557298, 16.25009, 50.89584], rtol=5e-7)
    np.testing.assert_allclose(result.frequencies_hz[::2], result.frequencies_hz[1::2], rtol=1e-12)

    def characteristic(x):
        c, s, ch, sh = np.cos(x), np.sin(x), np.cosh(x), np.sinh(x)
        return (1 + c * ch + x * (c * sh - s * ch)) / ch

    roots = np.array([brentq(characteristic, a, a + 1.0, xtol=1e-15) for a in (0.8, 3.6, 6.7)])
    assert relative_error(lam_squared, roots ** 2).max() <= 1e-8


def test_fixed_mesh_error_estimate_is_honest_and_refinement_converges():
    """With a given mesh the estimate bounds the true error; Hermite error ~ h⁴."""
    model = single_beam(CLAMPED, FREE, Iz=1.0, Iy=4.0, axial=False, torsion=False)
    exact = np.sort(np.concatenate([bending_hz("clamped-free", 4, I) for I in (1.0, 4.0)]))[:4]
    coarse, fine = (fe_frequencies(model, count=4, elements_per_beam=n) for n in (8, 16))
    for result in (coarse, fine):
        error = relative_error(result.frequencies_hz, exact)
        assert np.all(error <= result.error_estimate) and np.all(result.error_estimate < 50 * error)
    ratio = (relative_error(coarse.frequencies_hz, exact)
             / relative_error(fine.frequencies_hz, exact))
    np.testing.assert_allclose(ratio, 16, rtol=0.05)


@pytest.mark.parametrize("family", ["axial", "torsion", "bending"])
def test_dispersion_error_is_the_mesh_error_of_a_wave(family):
    """A fixed–fixed rod and a pinned–pinned beam on n elements have the mesh's Bloch
    waves as their modes (k = jπ/L), so each FE frequency's error against the closed
    form jπc/L or (jπ/L)² √(EI/ρA) is exactly dispersion_error at that frequency."""
    n, length = 8, 2.0
    if family == "bending":
        model = single_beam(PINNED, PINNED, length=length, E=3.0, rho=2.0, Iy=1e4, Iz=1.0,
                            axial=False, torsion=False)
        exact = (np.arange(1, 6) * np.pi / length) ** 2 * np.sqrt(3.0 / 2.0) / (2 * np.pi)
    else:
        rod = dict(E=5.0, axial=True, torsion=False) if family == "axial" else \
            dict(G=3.0, J=0.5, Ip=0.25, axial=False, torsion=True)
        model = single_beam(CLAMPED, CLAMPED, length=length, rho=2.0, Iy=1e6, Iz=1e6, **rod)
        speed = np.sqrt(5.0 / 2.0) if family == "axial" else np.sqrt(3.0 * 0.5 / (2.0 * 0.25))
        exact = np.arange(1, 6) * np.pi / length * speed / (2 * np.pi)
    computed = fe_frequencies(model, count=5, elements_per_beam=n, estimate_error=False).frequencies_hz
    predicted = [dispersion_error(model.beams[0], length / n, 2 * np.pi * f) for f in exact]
    np.testing.assert_allclose(relative_error(computed, exact), predicted, rtol=1e-6)
    assert min(predicted) > 1e-6  # each is a visible mesh error, not rounding


def test_estimates_stopped_at_the_mesh_cap_are_honest():
    """Refinement capped at 16 elements, the 40 lowest of a steel cantilever (bending
    in two planes, axial, torsion; closed forms): modes are matched by rank across
    meshes, and where a slowly converging one changed rank the extrapolation was off
    by up to 2.4× its estimate. The estimates above rtol include the finest mesh's
    dispersion error now. Where an estimate reaches 10 % (waves the mesh cannot
    resolve), that value and all above it are left out of the result and named
    in the note."""
    length, E, G, rho, area, Iy, Iz, J = 2.0, 2.1e11, 8.1e10, 7850.0, 1e-3, 2e-7, 2.6e-7, 4e-7
    model = single_beam(CLAMPED, FREE, length=length, E=E, G=G, rho=rho, A=area, Iy=Iy, Iz=Iz, J=J)
    quarter_waves = (2 * np.arange(1, 41) - 1) * np.pi / (2 * length) / (2 * np.pi)
    exact = np.sort(np.concatenate([bending_hz("clamped-free", 40, E * I, rho * area, length) for I in (Iy, Iz)]
                                   + [quarter_waves * np.sqrt(E / rho),
                                      quarter_waves * np.sqrt(G * J / (rho * (Iy + Iz)))]))[:40]
    result = fe_frequencies(model, count=40, max_elements_per_beam=16)
    assert result.elements_per_beam == 16 and "stopped at 16" in result.note
    reported = len(result.frequencies_hz)
    assert 10 <= reported < 40 and np.all(result.error_estimate < 0.1)
    assert f"{40 - reported} computed values not reported" in result.note
    error = relative_error(result.frequencies_hz, exact[:reported])
    assert np.all(error <= result.error_estimate), np.max(error / result.error_estimate)


def test_very_fine_mesh_keeps_the_low_modes():
    """4096 elements: the natural-factor solve keeps λ₁ to ~1e-14 (plain (K, M) would not)."""
    model = single_beam(CLAMPED, FREE, axial=False, torsion=False)
    result = fe_frequencies(model, count=2, elements_per_beam=4096, estimate_error=False)
    assert relative_error(result.frequencies_hz, bending_hz("clamped-free", 1, 1.0)).max() < 1e-13


def test_cantilever_through_massless_rigid_links():
    """Clamp and joint made of massless rigid bodies change nothing.

    The root is a port of a massless body fixed there; the two halves meet
    through two massless bodies sharing a hub point (rigidly joined there).
    """
    points = {"root": np.zeros(3), "start": np.zeros(3), "end1": np.array([0.5, 0, 0]),
              "hub": np.array([0.5, 0, 0]), "start2": np.array([0.5, 0, 0]),
              "tip": np.array([1.0, 0, 0])}
    properties = dict(Iz=1.0, Iy=2.25, axial=False, torsion=False)
    model = Model(
        name="jointed", points=points,
        beams=(make_beam("half1", points, "start", "end1", **properties),
               make_beam("half2", points, "start2", "tip", **properties)),
        rigids=(make_body("clamp", ["root", "start"], [0.0, 0.1, 0.0], 0.0),
                make_body("left", ["end1", "hub"], [0.5, 0.2, 0.0], 0.0),
                make_body("right", ["hub", "start2"], [0.4, 0.0, -0.3], 0.0)),
        boundary={"root": mask(CLAMPED)})
    exact = np.sort(np.concatenate([bending_hz("clamped-free", 4, I) for I in (1.0, 2.25)]))[:6]
    assert_honest(fe_frequencies(model, count=6), exact, 1e-8)


# --------------------------------------------------------------------------
# Springs and rigid bodies

def test_two_mass_chain_exact():
    """fixed–k–3m–k–m–k–fixed: ω² = (4 ∓ √7)/3 · k/m.

    From det [[2k − 3mω², −k], [−k, 2k − mω²]] = 0.
    """
    k, m = 7.0, 0.3
    exact = np.sqrt((4 + np.array([-1.0, 1.0]) * np.sqrt(7)) / 3 * k / m) / (2 * np.pi)
    for lateral in (INF, 1e3 * k):
        result = fe_frequencies(spring_chain([3 * m, m], k, lateral), count=2)
        assert relative_error(result.frequencies_hz, exact).max() <= 1e-12
        assert result.rigid_body_modes == 0


def test_long_chain_matches_the_lattice_formula():
    """N equal masses fixed at both ends: ω_j = 2 sqrt(k/m) sin(jπ / (2(N+1)))."""
    n, k, m = 2000, 3.0, 0.5
    result = fe_frequencies(spring_chain([m] * n, k), count=10)
    j = np.arange(1, 11)
    exact = 2 * np.sqrt(k / m) * np.sin(j * np.pi / (2 * (n + 1))) / (2 * np.pi)
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-9
    assert result.n_dof == n


def ring_of_three(k, m, guided):
    """1-D ring: three masses m, each spring k joins two of them in a closed loop.

    Body i spans ports at x = i and x = i + 1, except the third, whose second
    port is back at x = 0, so the springs (coinciding ends at x = 1, 2, 0)
    close the loop. Every other spring direction is rigid. ``guided``: also
    fix y, z and all rotations of every body (the rigid links are then
    redundant with those boundary conditions).
    """
    points, bodies, springs = {}, [], []
    for i in range(3):
        points[f"in{i}"] = np.array([i, 0.0, 0.0])
        points[f"out{i}"] = np.array([(i + 1) % 3, 0.0, 0.0])
        bodies.append(make_body(f"m{i}", [f"in{i}", f"out{i}"], [i + 0.5, 0.0, 0.0], m, (m, m, m)))
        springs.append(make_spring(f"k{i}", f"out{i}", f"in{(i + 1) % 3}", [k] + [INF] * 5))
    boundary = {f"in{i}": mask(COMPONENTS[1:]) for i in range(3)} if guided else {}
    return Model(name="ring", points=points, rigids=tuple(bodies), springs=tuple(springs),
                 boundary=boundary)


@pytest.mark.parametrize("guided, rigid", [(True, 1), (False, 6)])
def test_ring_of_three_masses(guided, rigid):
    """Cyclic 3-mass chain: K = k [[2,−1,−1], [−1,2,−1], [−1,−1,2]], ω² = 0, 3k/m, 3k/m."""
    k, m = 2.0, 0.7
    result = fe_frequencies(ring_of_three(k, m, guided), count=4)
    assert result.rigid_body_modes == rigid
    exact = np.full(2, np.sqrt(3 * k / m) / (2 * np.pi))
    assert len(result.frequencies_hz) == 2
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-12


def two_bodies_on_a_spring(k, axes=None, offsets=((0, 0, 0), (0, 0, 0))):
    """Two free rigid bodies joined by a spring; mass centres offset from it (m).

    With zero offsets the six spring directions are uncoupled.
    """
    joint = np.array([0.3, -0.2, 0.5])
    points = {"a": joint, "b": joint.copy()}
    bodies = (make_body("one", ["a"], joint + offsets[0], 2.0, (0.3, 0.4, 0.5)),
              make_body("two", ["b"], joint + offsets[1], 3.0, (0.6, 0.2, 0.7)))
    return Model(name="pair", points=points, rigids=bodies,
                 springs=(make_spring("joint", "a", "b", k, axes),))


def test_free_floating_bodies_on_a_spring():
    """Six rigid-body modes; per direction ω² = k_i (1/m₁ + 1/m₂), k_ri (1/J₁ + 1/J₂)."""
    k = np.array([10.0, 20.0, 30.0, 4.0, 5.0, 6.0])
    result = fe_frequencies(two_bodies_on_a_spring(k), count=10)
    assert result.rigid_body_modes == 6
    inverse_mass = np.r_[[1 / 2 + 1 / 3] * 3,
                         1 / np.array([0.3, 0.4, 0.5]) + 1 / np.array([0.6, 0.2, 0.7])]
    exact = np.sort(np.sqrt(k * inverse_mass)) / (2 * np.pi)
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-12


def test_inf_spring_is_the_limit_of_stiff_springs():
    """Rigid directions (inf) = the limit of ever stiffer springs; the gap ~ 1/stiffness.

    Mass centres off the joint couple its translations and rotations.
    """
    k = np.array([10.0, 20.0, 30.0])
    axes = local_axes([1.0, 1.0, 0.0], y_hint=(0.0, 0.3, 1.0))
    offsets = ((0.5, 0.0, 0.1), (0.0, -0.4, 0.2))
    rigid = fe_frequencies(two_bodies_on_a_spring(np.r_[k, INF, INF, INF], axes, offsets), count=3)
    assert rigid.rigid_body_modes == 6 and len(rigid.frequencies_hz) == 3
    gaps = []
    for stiff in (1e4, 1e6):
        soft = fe_frequencies(two_bodies_on_a_spring(np.r_[k, [stiff] * 3], axes, offsets), count=3)
        gaps.append(relative_error(soft.frequencies_hz, rigid.frequencies_hz).max())
    assert gaps[1] < 2e-5 and gaps[1] < gaps[0] / 50


# --------------------------------------------------------------------------
# Massless beams, rigid axial/torsion

def test_massless_beam_between_two_rigid_masses():
    """ρ = 0: the beam is a pure spring; its cubic mesh is exact for any n.

    Axial ω² = EA/L (1/m₁ + 1/m₂), torsion ω² = GJ/L (1/J₁ + 1/J₂); bending in
    each plane from the exact 4x4 static stiffness of the end (w, θ) pairs.
    """
    L, E, G, A, I, J = 2.0, 5.0, 3.0, 0.4, 0.2, 0.3
    points = {"a": np.zeros(3), "b": np.array([0.0, L, 0.0])}
    beam = make_beam("link", points, "a", "b", E=E, G=G, rho=0.0, A=A, Iy=I, Iz=I, J=J)
    bodies = (make_body("one", ["a"], points["a"], 2.0, (0.5, 0.5, 0.5)),
              make_body("two", ["b"], points["b"], 3.0, (0.7, 0.7, 0.7)))
    model = Model(name="dumbbell", points=points, beams=(beam,), rigids=bodies)
    axial = E * A / L * (1 / 2 + 1 / 3)
    torsion = G * J / L * (1 / 0.5 + 1 / 0.7)
    end_masses = np.diag([2.0, 0.5, 3.0, 0.7])
    bending = np.linalg.eigvals(np.linalg.solve(end_masses, hermite_stiffness(E * I, L))).real
    bending = np.sort(bending)[2:]                   # two rigid (translation, rotation)
    exact = np.sqrt(np.sort(np.r_[axial, torsion, bending, bending])) / (2 * np.pi)
    for n in (1, 8):
        result = fe_frequencies(model, count=10, elements_per_beam=n)
        assert result.rigid_body_modes == 6
        assert relative_error(result.frequencies_hz, exact).max() <= 1e-11


def test_axially_rigid_beam_keeps_its_axial_inertia():
    """A skew, axially rigid cantilever hung on an axial spring k: ω² = k / (ρ A L).

    The root spring is rigid in every other direction, so the bending modes
    are those of a cantilever (torsionally rigid, so no torsion modes).
    """
    direction = np.array([2.0, -1.0, 2.0]) / 3.0
    axes = local_axes(direction)
    points = {"ground": np.zeros(3), "root": np.zeros(3), "tip": direction * 1.0}
    beam = make_beam("arm", points, "root", "tip", rho=2.0, A=0.5, axial=False, torsion=False)
    k = 0.5
    model = Model(name="hung", points=points, beams=(beam,),
                  springs=(make_spring("hanger", "ground", "root", [k] + [INF] * 5, axes),),
                  boundary={"ground": mask(CLAMPED)})
    result = fe_frequencies(model, count=5)
    beam_mass = 2.0 * 0.5 * 1.0
    exact = np.r_[np.sqrt(k / beam_mass) / (2 * np.pi),
                  np.repeat(bending_hz("clamped-free", 2, 1.0, 2.0 * 0.5), 2)]
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-9


# --------------------------------------------------------------------------
# Massless points: condensed out statically, never taken for modes

#: Stiffness of every spring of this section, N/m and N m/rad.
SPRING = np.array([10.0, 20.0, 30.0, 4.0, 5.0, 6.0])


def with_dangling_spring(model, at, loose_end="spring") -> Model:
    """``model`` plus a spring from point ``at`` to a new point "loose" that carries
    no mass; ``loose_end="beam"`` hangs a massless beam on that point too."""
    points = {**model.points, "loose": np.asarray(model.points[at], float).copy()}
    springs = model.springs + (make_spring("dangling", at, "loose", SPRING),)
    beams = model.beams
    if loose_end == "beam":
        points["far"] = points["loose"] + np.array([0.0, 0.0, 1.0])
        beams += (make_beam("massless", points, "loose", "far", rho=0.0),)
    return replace(model, points=points, springs=springs, beams=beams)


def one_body() -> Model:
    """A free 3.5 kg body with one port off its mass centre."""
    points = {"port": np.array([0.2, 0.1, 0.0])}
    return Model(name="body", points=points,
                 rigids=(make_body("body", ["port"], [0.0, 0.0, 0.0], 3.5, (0.1, 0.2, 0.3)),))


def welded_pair() -> Model:
    """Two free bodies sharing their one port, so rigidly joined there."""
    hub = np.array([0.3, -0.2, 0.5])
    return Model(name="welded", points={"hub": hub},
                 rigids=(make_body("one", ["hub"], hub + [0.5, 0.0, 0.1], 2.0, (0.3, 0.4, 0.5)),
                         make_body("two", ["hub"], hub + [0.0, -0.4, 0.2], 1.5, (0.6, 0.2, 0.7))))


@pytest.mark.parametrize("build, at", [(one_body, "port"), (welded_pair, "hub")], ids=["body", "welded"])
@pytest.mark.parametrize("loose_end", ["spring", "beam"])
def test_rigid_mass_with_a_dangling_spring_has_no_elastic_mode(build, at, loose_end):
    """All the mass moves rigidly and the spring's far end (with a massless beam on it)
    carries none: six rigid-body modes and no elastic one, by both routes."""
    model = with_dangling_spring(build(), at, loose_end)
    fe = fe_frequencies(model, count=10)
    mstmm = natural_frequencies(model, count=10)
    assert len(fe.frequencies_hz) == len(mstmm.frequencies_hz) == 0
    assert fe.rigid_body_modes == mstmm.rigid_body_modes == 6
    if loose_end == "spring":
        assert fe.note.startswith("only 0 elastic natural frequencies exist")


def test_free_two_mass_chain_with_massless_ends():
    """Two free bodies joined by a spring (mass centres on it), a spring dangling from
    each: per direction ω² = k_i (1/m₁ + 1/m₂) or k_ri (1/J₁ + 1/J₂), six in all."""
    pair = two_bodies_on_a_spring(SPRING)
    model = with_dangling_spring(replace(pair, points={**pair.points, "b2": pair.points["b"].copy()},
                                         springs=pair.springs + (make_spring("end", "a", "b2", SPRING),)), "b")
    result = fe_frequencies(model, count=10)
    inverse_mass = np.r_[[1 / 2 + 1 / 3] * 3, 1 / np.array([0.3, 0.4, 0.5]) + 1 / np.array([0.6, 0.2, 0.7])]
    exact = np.sort(np.sqrt(SPRING * inverse_mass)) / (2 * np.pi)
    assert result.rigid_body_modes == 6 and len(result.frequencies_hz) == 6
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-12


@pytest.mark.parametrize("junctions", [1, 3])
def test_massless_junctions_between_springs_in_series(junctions):
    """ground –k– j₁ –k– … j_n –2k– body, the junctions massless, the body's mass
    centre at its port: per direction ω² = k_s / m or k_s / J_i with the series
    stiffness 1/k_s = n/k + 1/(2k)."""
    m, inertia = 2.0, np.array([0.1, 0.2, 0.3])
    names = ["ground"] + [f"j{i}" for i in range(junctions)] + ["port"]
    points = {name: np.array([0.1, 0.2, 0.3]) for name in names}
    springs = tuple(make_spring(f"k{i}", a, b, SPRING * (2.0 if b == "port" else 1.0))
                    for i, (a, b) in enumerate(zip(names[:-1], names[1:])))
    model = Model(name="series", points=points, springs=springs,
                  rigids=(make_body("body", ["port"], points["port"], m, inertia),),
                  boundary={"ground": mask(CLAMPED)})
    series = 1.0 / (junctions / SPRING + 1.0 / (2.0 * SPRING))
    exact = np.sort(np.sqrt(series / np.r_[[m] * 3, inertia])) / (2 * np.pi)
    result = fe_frequencies(model, count=10)
    assert result.rigid_body_modes == 0 and len(result.frequencies_hz) == 6
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-12


def test_singular_inertia_in_skew_axes_has_a_direction_without_mass():
    """A body whose inertia tensor is singular in axes skew to the model's (a
    direction without mass that no DOF is aligned with) on a spring to ground, a
    spring dangling from it: five elastic modes, as the transfer-matrix route finds."""
    axis = np.array([1.0, -1.0, 0.0]) / np.sqrt(2.0)  # a thin rod along a skew axis: no inertia about it
    skew = 0.1 * (np.eye(3) - np.outer(axis, axis))
    points = {"ground": np.zeros(3), "port": np.zeros(3)}
    model = with_dangling_spring(Model(name="skew", points=points,
                                       rigids=(make_body("body", ["port"], [0.1, 0.0, 0.0], 2.0, skew),),
                                       springs=(make_spring("hold", "ground", "port", SPRING),),
                                       boundary={"ground": mask(CLAMPED)}), "port")
    fe, mstmm = fe_frequencies(model, count=10), natural_frequencies(model, count=10)
    assert len(fe.frequencies_hz) == len(mstmm.frequencies_hz) == 5
    assert relative_error(fe.frequencies_hz, mstmm.frequencies_hz).max() <= 1e-10


def with_junctions(model) -> Model:
    """``model`` with every spring cut into two of its stiffness in series, joined
    at a new massless point (the pair is half as stiff)."""
    points, springs = dict(model.points), []
    for spring in model.springs:
        a, b = spring.ends
        points[f"{spring.name}_junction"] = np.asarray(points[a], float).copy()
        springs += [replace(spring, name=f"{spring.name}_a", ends=(a, f"{spring.name}_junction")),
                    replace(spring, name=f"{spring.name}_b", ends=(f"{spring.name}_junction", b))]
    return replace(model, points=points, springs=tuple(springs))


def test_long_chain_with_massless_junctions_matches_the_lattice_formula():
    """300 equal masses fixed at both ends, each spring k made of two springs in
    series (301 massless junctions, solved by Lanczos): the lattice of k/2,
    ω_j = 2 sqrt(k / 2m) sin(jπ / (2(N+1)))."""
    n, k, m = 300, 3.0, 0.5
    model = with_junctions(spring_chain([m] * n, k))
    result = fe_frequencies(model, count=10)
    j = np.arange(1, 11)
    exact = 2 * np.sqrt(k / (2 * m)) * np.sin(j * np.pi / (2 * (n + 1))) / (2 * np.pi)
    assert result.n_dof == 2 * n + 1 and result.n_dof > DENSE_LIMIT
    assert relative_error(result.frequencies_hz, exact).max() <= 1e-9


def in_millimetres_and_grams(model) -> Model:
    """``model`` with lengths in mm and masses in g (spring stiffness in g/s² and
    g mm²/s² per rad): the same physics, so the same frequencies."""
    mm, g = 1e3, 1e3
    scale_k = np.r_[[g] * 3, [g * mm ** 2] * 3]
    return replace(model, points={p: x * mm for p, x in model.points.items()},
                   rigids=tuple(replace(b, mass=b.mass * g, com=b.com * mm, inertia=b.inertia * g * mm ** 2)
                                for b in model.rigids),
                   springs=tuple(replace(s, k=s.k * scale_k) for s in model.springs))


@pytest.mark.parametrize("ratio, modes", [(1e-16, 0), (1e-6, 6)])
def test_negligible_mass_is_judged_against_the_model_s_own_scale(ratio, modes):
    """A small body on the dangling spring of the 3.5 kg body: at 1e-16 of its mass
    and inertia it is rounding (no elastic mode), at 1e-6 it is mass (six modes, per
    direction ω² = k_i (1/m + 1/M) with both mass centres at the spring), in SI and in
    millimetres and grams alike."""
    body = one_body()
    model = with_dangling_spring(replace(body, rigids=(replace(body.rigids[0], com=body.points["port"]),)), "port")
    big = model.rigids[0]
    small = make_body("small", ["loose"], model.points["loose"], ratio * big.mass, ratio * np.diag(big.inertia))
    model = replace(model, rigids=model.rigids + (small,))
    inverse_mass = (1 + 1 / ratio) / np.r_[[big.mass] * 3, np.diag(big.inertia)]
    exact = np.sort(np.sqrt(SPRING * inverse_mass))[:modes] / (2 * np.pi)
    for variant in (model, in_millimetres_and_grams(model)):
        result = fe_frequencies(variant, count=10)
        assert result.rigid_body_modes == 6 and len(result.frequencies_hz) == modes
        assert relative_error(result.frequencies_hz, exact).max(initial=0.0) <= 1e-9


# --------------------------------------------------------------------------
# API

def test_assembled_matrices_and_dof_index():
    """M, K symmetric; T has identity rows at the reduced DOFs; clamped root stays put."""
    model = single_beam(CLAMPED, FREE, Iz=0.01, Iy=0.04)   # bending below axial and torsion
    fe = assemble(model, elements_per_beam=6)
    for matrix in (fe.M, fe.K):
        assert abs(matrix - matrix.T).max() <= 1e-14 * abs(matrix).max()
    assert fe.T.shape == (fe.n_full, fe.n_dof) and fe.n_dof == 6 * 6
    lam, X, _ = fe_modes(fe, count=3)
    np.testing.assert_allclose(X.T @ fe.M @ X, np.eye(3), atol=1e-12)
    shapes = fe.T @ X
    assert np.all(shapes[fe.dof_index.point("a")] == 0.0)
    tip = shapes[fe.dof_index.point("b")]
    np.testing.assert_allclose(fe.beam_motion("beam", shapes[:, 0])[-1], tip[:, 0], atol=1e-15)
    # the first mode bends in the x-y plane: only uy and θz move
    assert abs(tip[1, 0]) > 0 and np.allclose(tip[[0, 2, 3, 4], 0], 0, atol=1e-12)


def test_result_dictionary_and_fmax():
    """``fmax`` keeps all frequencies up to it; ``to_dict`` has the contract keys."""
    model = single_beam(CLAMPED, FREE, Iz=1.0, Iy=1.0, axial=False, torsion=False)
    exact = bending_hz("clamped-free", 3, 1.0)
    result = fe_frequencies(model, count=None, fmax=exact[2] * 1.01, mode_shapes=True)
    assert relative_error(result.frequencies_hz, np.repeat(exact, 2)).max() <= 1e-9
    assert result.mode_shapes.shape == (assemble(model, result.elements_per_beam).n_full, 6)
    assert len(fe_frequencies(model, count=3, fmax=exact[2] * 1.01).frequencies_hz) == 3
    data = result.to_dict()
    assert set(data) == {"model", "frequencies_hz", "rigid_body_modes", "n_dof",
                         "elements_per_beam", "error_estimate", "seconds", "method"}
    assert data["method"] == "fe" and data["rigid_body_modes"] == 0


def test_a_krylov_space_wider_than_the_massive_dofs_is_not_asked_for():
    """Random tree 17 on 32 elements per beam: 204 DOFs, 198 with mass. 80 modes asked
    ARPACK for 201 Lanczos vectors, more than K⁺M's rank, and it stopped ("could not
    build an Arnoldi factorization"); such a model is solved densely, and its modes
    satisfy K x = λ M x."""
    fe = assemble(random_model("tree", 17), 32)
    lam, X, _ = fe_modes(fe, 80)
    assert len(lam) == 80
    residual = fe.K @ X - (fe.M @ X) * lam
    assert np.abs(residual).max() <= 1e-8 * np.abs(fe.K @ X).max()
