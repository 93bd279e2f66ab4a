"""Roots float64 counts as multiple that are clusters of simple roots in the model's exact data.

Two bending planes whose second moments are a hair apart, or a symmetric model
turned in space (its frames and spring axes rounded to float64), have pairs of
simple roots closer than float64 resolves: the mpmath refinement must give each
member, not refuse the model. References: the cantilever's closed form
(ω ∝ √I per bending plane), the same model upright (a rigid rotation changes
no frequency), and the FE route.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from builders import fixed, make_beam, make_spring
from scipy.spatial.transform import Rotation

import linmstmm as lm

STEEL_ROD = dict(material=dict(E=2.0e11, G=8.0e10, rho=7800.0), A=1.0e-3, Iy=3.0e-7, J=2.0e-7, Ip=4.2e-7)


def cantilever(iz: float, shear: float = 8.0e10) -> lm.Model:
    """A 1.5 m steel cantilever along x, clamped at "root", with Iz = ``iz`` m⁴ and the
    shear modulus ``shear`` (Pa)."""
    points = {"root": np.zeros(3), "tip": np.array([1.5, 0.0, 0.0])}
    rod = {**STEEL_ROD, "material": {**STEEL_ROD["material"], "G": shear}}
    beam = make_beam("b", "root", "tip", points, Iz=iz, **rod)
    return lm.Model("cantilever", points, beams=(beam,), boundary={"root": fixed()})


def strut_on_a_ball_joint(turn: np.ndarray) -> lm.Model:
    """The ball-joint example of docs/model-format.md with every position and axis
    turned by the rotation matrix ``turn``."""
    points = {name: turn @ np.array(x, float) for name, x in
              (("ground", (0, 0, 0)), ("foot", (0, 0, 0)), ("head", (1, 1, 0)), ("anchor", (1, 1, 0)))}
    strut = make_beam("strut", "foot", "head", points, y_hint=turn @ np.array([-1.0, 1.0, 0.0]), A=5.0e-4,
                      Iy=5.0e-8, Iz=5.0e-8, J=1.0e-7)
    rotations = ["rx", "ry", "rz"]
    springs = (make_spring("ball", "ground", "foot", [np.inf] * 3 + [0.0] * 3, axes=turn.T, release=rotations),
               make_spring("stay", "anchor", "head", [2.0e5] * 3 + [0.0] * 3, axes=turn.T, release=rotations))
    return lm.Model("strut on a ball joint", points, beams=(strut,), springs=springs,
                    boundary={"anchor": fixed(), "ground": fixed()})


def first_bending_hz(second_moment) -> mp.mpf:
    """The cantilever's first bending frequency in a plane of ``second_moment`` (m⁴), Hz:
    (β₁/L)² √(E I / ρA) / 2π, β₁ the first root of cos β cosh β + 1."""
    beta = mp.findroot(lambda x: mp.cos(x) * mp.cosh(x) + 1, 1.875)
    stiffness = mp.mpf(2.0e11) * mp.mpf(second_moment) / (mp.mpf(7800.0) * mp.mpf(1.0e-3))
    return (beta / mp.mpf(1.5)) ** 2 * mp.sqrt(stiffness) / (2 * mp.pi)


def test_cluster_polynomial_roots_and_slope_whatever_the_mpmath_order():
    """The cluster separation's polynomial, lowest power first, gives the same roots and
    slope in mpmath 1.3 (highest power first only) and 1.4 (which deprecates that order)."""
    from linmstmm.precision import _horner, _polynomial_roots

    with mp.workdps(30):
        roots = [mp.mpf("0.25"), mp.mpf("-1.5"), mp.mpf(3)]
        ascending = [-roots[0] * roots[1] * roots[2], roots[0] * roots[1] + roots[0] * roots[2]
                     + roots[1] * roots[2], -sum(roots), mp.mpf(1)]  # (t − r0)(t − r1)(t − r2)
        got = sorted(_polynomial_roots(ascending), key=lambda t: mp.re(t))
        assert max(abs(g - r) for g, r in zip(got, sorted(roots))) < mp.mpf(10) ** -25
        slopes = [k * ascending[k] for k in range(3, 0, -1)]
        t = mp.mpf("0.7")
        product_rule = sum((t - a) * (t - b) for a, b in ((roots[1], roots[2]), (roots[0], roots[2]),
                                                          (roots[0], roots[1])))
        assert abs(_horner(slopes, t) - product_rule) < mp.mpf(10) ** -25


def test_bending_pair_one_ulp_apart_refines_to_twenty_digits():
    """Iz one ulp above Iy: ω = (β₁/L)² √(E I / ρA) for I = Iy and I = Iz,
    β₁ the first root of cos β cosh β + 1 (``digits=20`` stopped: the 2-fold
    root does not settle in mpmath)."""
    iy = 3.0e-7
    iz = float(np.nextafter(iy, 1.0))
    result = lm.natural_frequencies(cantilever(iz), count=2, digits=20)
    with mp.workdps(40):
        beta = mp.findroot(lambda x: mp.cos(x) * mp.cosh(x) + 1, 1.875)
        exact = [(beta / mp.mpf(1.5)) ** 2 * mp.sqrt(mp.mpf(2.0e11) * mp.mpf(i) / (mp.mpf(7800.0) * mp.mpf(1.0e-3)))
                 / (2 * mp.pi) for i in (iy, iz)]
        got = [mp.mpf(text) for text in result.frequencies_text]
        assert max(abs(g / e - 1) for g, e in zip(got, exact)) < mp.mpf(10) ** -18


@pytest.mark.parametrize("split", [1e-9, 1e-12, 1e-14])
def test_bending_pairs_a_hair_apart_come_out_as_two_roots(split):
    """Iz = Iy (1 + split): the pair is √(1 + split) apart, each to 20 digits."""
    iy, iz = 3.0e-7, 3.0e-7 * (1 + split)
    result = lm.natural_frequencies(cantilever(iz), count=2, digits=20)
    with mp.workdps(40):
        got = [mp.mpf(text) for text in result.frequencies_text]
        exact = [first_bending_hz(iy), first_bending_hz(iz)]
        assert max(abs(g / e - 1) for g, e in zip(got, exact)) < mp.mpf(10) ** -18


def cantilever_hz(iz: float, count: int, shear: float = 8.0e10) -> np.ndarray:
    """The steel cantilever's ``count`` lowest frequencies (Hz) in closed form: bending
    in each plane (:func:`bending_hz`); axial and torsion, (2n − 1) c / 4L with
    c = √(E/ρ) and √(G J / ρ Ip)."""
    bending = [bending_hz(k, i) for k in range(1, count + 1) for i in (3.0e-7, iz)]
    waves = [np.sqrt(2.0e11 / 7800.0), np.sqrt(shear * 2.0e-7 / (7800.0 * 4.2e-7))]
    other = [(2 * n - 1) * c / (4 * 1.5) for c in waves for n in range(1, count + 1)]
    return np.sort(bending + other)[:count]


@pytest.mark.parametrize("gap, rtol", [(1e-6, None), (1e-7, None), (1e-8, None), (1e-7, 1e-6), (1e-4, 1e-4)])
def test_bending_pairs_closer_than_a_count_resolves_are_each_found(gap, rtol):
    """Planes √(Iz/Iy) − 1 = ``gap`` apart, 30 lowest: every one within rtol
    (1e-9 by default) of the closed form (:func:`cantilever_hz`). Counts over a
    circle or across a root that held a member of a pair took the pair for a double
    root: at the default rtol the pair at 1.85 kHz 1e-6 apart came out as one
    double root 1e-6 from one of them, 1e-7 apart a root 3e-3 below a pair went
    missing, and at rtol 1e-4 with planes 1e-4 apart only 29 came back, with the
    note that no more exist."""
    iz = 3.0e-7 * (1 + gap) ** 2
    result = lm.natural_frequencies(cantilever(iz), count=30, rtol=rtol)
    np.testing.assert_allclose(result.frequencies_hz, cantilever_hz(iz, 30), rtol=rtol or 1e-9)


@pytest.mark.parametrize("gap, rtol", [(1e-7, 1e-6), (2e-8, 1e-7), (1e-7, 1e-7)])
def test_close_pairs_a_loose_rtol_parts_stay_parted(gap, rtol):
    """At an rtol looser than the default the searches may list a pair closer than rtol
    as one value twice, within rtol of both (docs/api.md; a pair 1e-8 apart at rtol
    1e-6 so). Where they part the pairs, as in these three cases, the default rtol's
    shortcuts (segment ends moved off undecided counts, repairs halved in a wide gap)
    must not merge them: applied at these rtols they gave nine false double roots
    with the upper members lost (1e-7 apart at rtol 1e-6), and an UnsettledRoot in
    mpmath (2e-8 apart at rtol 1e-7)."""
    iz = 3.0e-7 * (1 + gap) ** 2
    result = lm.natural_frequencies(cantilever(iz), count=30, rtol=rtol)
    exact = cantilever_hz(iz, 30)
    assert len(set(result.frequencies_hz.tolist())) == len(set(exact.tolist()))
    np.testing.assert_allclose(result.frequencies_hz, exact, rtol=rtol)


def bending_hz(k: int, second_moment: float) -> float:
    """The steel cantilever's k-th bending frequency in a plane of ``second_moment`` (m⁴),
    Hz: (β/L)² √(E I / ρA) / 2π, β the k-th root of cos β + 1 / cosh β (cos β cosh β + 1
    = 0 divided by cosh β, which keeps it near 1 at large β)."""
    with mp.workdps(30):
        beta = mp.findroot(lambda x: mp.cos(x) + 1 / mp.cosh(x), (k - 0.5) * mp.pi)
        stiffness = mp.mpf(2.0e11) * mp.mpf(second_moment) / (mp.mpf(7800.0) * mp.mpf(1.0e-3))
        return float((beta / mp.mpf(1.5)) ** 2 * mp.sqrt(stiffness) / (2 * mp.pi))


def torsion_beside_bending(k: int, offset: float) -> float:
    """The shear modulus (Pa) that puts the steel cantilever's first torsion root,
    √(G J / ρ Ip) / 4L Hz, ``offset`` (relative) above its k-th bending root."""
    return (4 * 1.5 * bending_hz(k, 3.0e-7) * (1 + offset)) ** 2 * 7800.0 * 4.2e-7 / 2.0e-7


@pytest.mark.parametrize("engine", ["compiled", "numpy"])
@pytest.mark.parametrize("k, offset", [(k, offset) for k in (3, 6, 8)
                                       for offset in (-1e-4, -1e-5, -1e-6, 1e-6, 5e-6, 2e-5, 1e-4)])
def test_a_double_root_with_a_simple_one_close_beside_it(k, offset, engine):
    """Equal bending planes (every bending root double) and the first torsion root
    ``offset`` (relative) from the k-th: every count from just below the double root
    to past the torsion root gives the closed form (:func:`cantilever_hz`) to 1e-9.
    With the torsion root just above, a count that ended on the double root gave it
    once with the torsion root in its place, or stopped in mpmath refining it as a
    simple root ("does not settle ... at 172 digits")."""
    shear = torsion_beside_bending(k, offset)
    model = cantilever(3.0e-7, shear)
    exact = cantilever_hz(3.0e-7, 2 * k + 4, shear)
    for count in range(2 * k - 2, 2 * k + 4):
        result = lm.natural_frequencies(model, count, engine=engine)
        np.testing.assert_allclose(result.frequencies_hz, exact[:count], rtol=1e-9, atol=0,
                                   err_msg=f"count {count}")
        assert result.note == ""


@pytest.mark.parametrize("gap", [1e-6, 1e-7])
def test_bending_pairs_a_hair_apart_up_to_a_frequency(gap):
    """The same rods, every frequency up to 5.6 kHz (31): the search up to a
    frequency had each pair as one double root 1e-6 off, or stopped in mpmath."""
    iz = 3.0e-7 * (1 + gap) ** 2
    result = lm.natural_frequencies(cantilever(iz), count=None, fmax=5600.0)
    np.testing.assert_allclose(result.frequencies_hz, cantilever_hz(iz, 31), rtol=1e-9)


def test_a_turned_strut_on_a_ball_joint_has_the_frequencies_of_the_upright_one():
    """Frequencies do not depend on the frame: the example turned by 0.7 rad about
    (1, 2, 3) has those of the example as written, eight lowest, pairs equal by
    axial symmetry (it stopped: "the 2-fold root near 578.6 rad/s does not
    settle in mpmath")."""
    axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turn = np.eye(3) + np.sin(0.7) * cross + (1 - np.cos(0.7)) * cross @ cross
    upright = lm.natural_frequencies(strut_on_a_ball_joint(np.eye(3)), count=8).frequencies_hz
    turned = lm.natural_frequencies(strut_on_a_ball_joint(turn), count=8).frequencies_hz
    np.testing.assert_allclose(turned, upright, rtol=1e-12)


@pytest.mark.parametrize("seed", range(1, 9))
def test_randomly_turned_struts_agree_with_the_upright_one_and_the_fe_route(seed):
    """Eight random turns: the upright model's eight lowest frequencies (a rigid
    rotation changes none), and the FE route's on the turned model."""
    turn = Rotation.random(random_state=seed).as_matrix()
    model = strut_on_a_ball_joint(turn)
    turned = lm.natural_frequencies(model, count=8)
    upright = lm.natural_frequencies(strut_on_a_ball_joint(np.eye(3)), count=8)
    np.testing.assert_allclose(turned.frequencies_hz, upright.frequencies_hz, rtol=1e-12)
    assert turned.rigid_body_modes == upright.rigid_body_modes == 1
    check = lm.fe_frequencies(model, count=8)
    np.testing.assert_allclose(turned.frequencies_hz, check.frequencies_hz,
                               rtol=max(1e-9, 3 * float(np.nanmax(check.error_estimate))))


def test_mode_shapes_of_a_turned_strut():
    """The mode shapes of a turned strut: its frequencies, mass-normalised (modal
    masses 1 kg), the members of each pair orthogonal."""
    model = strut_on_a_ball_joint(Rotation.random(random_state=1).as_matrix())
    modes = lm.mode_shapes(model, count=4)
    upright = lm.natural_frequencies(strut_on_a_ball_joint(np.eye(3)), count=4)
    elastic = slice(modes.rigid_body_modes, None)
    np.testing.assert_allclose(modes.frequencies_hz[elastic], upright.frequencies_hz, rtol=1e-12)
    np.testing.assert_allclose(modes.modal_mass[elastic], 1.0, rtol=1e-9)
    assert modes.mass_orthogonality_error < 1e-8


def test_a_copy_taken_from_a_multiple_root_leaves_it_the_others(monkeypatch):
    """A root listed six times (three double roots 5e-9 apart that the list held as one)
    whose pencil shows the highest beside it gives that root one copy and keeps five: its
    multiplicity is recorded as five. Where no count had recorded one it was recorded as
    one, and the later check of multiplicities took it for a simple root: an octahedral
    star's 20 lowest (bending planes 1e-8 apart) came back with the highest double root
    in place of the lowest one's second copy, 1e-8 high and without a note."""
    from types import SimpleNamespace

    from linmstmm.roots import clusters

    root, beside = 10.0, 10.0 * (1 + 1e-8)
    monkeypatch.setattr(clusters, "offsets_of", lambda finder, roots, copies: dict.fromkeys(roots))
    monkeypatch.setattr(clusters, "beside", lambda finder, polished: [[beside] for _ in polished])
    monkeypatch.setattr(clusters, "_holds_its_copies", lambda *arguments: False)  # the count beside it finds fewer
    finder = SimpleNamespace(_counted={}, rtol=1e-9)
    assert clusters._apart_by_offsets(finder, [root] * 6, {root: 6}) == [root] * 5 + [beside]
    assert finder._counted[root] == 5


def test_a_cluster_whose_copies_lie_beyond_the_circle_is_found_again_by_its_count():
    """A list that holds a cluster's middle member twice and its upper one not at all
    (three roots 4.8e-6 apart on an octahedral star of one beam an arm, bending planes
    1e-5 apart): the circle about the doubled root, half the distance to the lowest, holds
    one root, and the second copy was dropped (or, at the default rtol, the search for an
    octahedral star's 22 lowest with its planes 1e-8 apart came back with 21, the 21st
    5e-9 off). The cluster is found again by bisection on the count of the stretch SPLIT
    beyond its members: all three, within the default rtol of those the search finds."""
    from linmstmm.builders import beam_star
    from linmstmm.roots import clusters
    from linmstmm.solve import frequency_finder

    model = beam_star(1, 1e-5)
    true = frequency_finder(model)[1].find(12, None).roots
    _, finder, _ = frequency_finder(model)
    doubled = [true[0], true[1], true[1], *true[3:]]
    placed, replaced = clusters._cluster_isolated(finder, doubled, true[1])
    assert replaced == {true[0], true[1]}
    np.testing.assert_allclose(sorted(placed), true, rtol=1e-9)
