"""Numerical stability at the extremes, each against a closed form.

Discrete references are the eigenvalues of the K, M matrices written by hand
in the test and solved in mpmath at 50 digits (independent of the transfer
matrices); beam references are roots of the classical frequency equations.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
from builders import fixed, make_beam, make_rigid, make_spring, single_beam_model

from linmstmm.model import Model
from linmstmm.solve import frequency_finder, natural_frequencies


def chain_along_x(masses, stiffnesses, right_end_fixed=False, name="chain"):
    """ground–k0–m0–k1–m1–…: point masses, isotropic translational springs, rotations locked.

    Every translation direction repeats the 1-D chain, so each frequency is triple.
    """
    n = len(masses)
    points = {"g": np.zeros(3)}
    rigids, springs = [], []
    for i, (m, k) in enumerate(zip(masses, stiffnesses)):
        points[f"a{i}"] = np.array([float(i), 0.0, 0.0])
        points[f"b{i}"] = np.array([i + 1.0, 0.0, 0.0])
        before = "g" if i == 0 else f"b{i - 1}"
        springs.append(make_spring(f"k{i}", before, f"a{i}", [k, k, k, np.inf, np.inf, np.inf]))
        rigids.append(make_rigid(f"m{i}", [f"a{i}", f"b{i}"], m, [i + 0.5, 0.0, 0.0]))
    boundary = {"g": fixed()}
    if right_end_fixed:
        points["h"] = points[f"b{n - 1}"].copy()
        k = stiffnesses[n]
        springs.append(make_spring(f"k{n}", f"b{n - 1}", "h", [k, k, k, np.inf, np.inf, np.inf]))
        boundary["h"] = fixed()
    return Model(name, points, rigids=tuple(rigids), springs=tuple(springs), boundary=boundary)


def chain_reference_hz(masses, stiffnesses, right_end_fixed=False):
    """Eigenfrequencies of the 1-D chain from its K and M in mpmath (50 digits), Hz."""
    return np.array([float(f) for f in chain_reference_mp(masses, stiffnesses, right_end_fixed)])


def chain_reference_mp(masses, stiffnesses, right_end_fixed=False):
    """The same as mpf values at 50 digits, ascending."""
    with mp.workdps(50):
        n = len(masses)
        K = mp.zeros(n, n)
        for i in range(n):
            K[i, i] += stiffnesses[i]
            if i > 0:
                K[i, i - 1] -= stiffnesses[i]
                K[i - 1, i] -= stiffnesses[i]
                K[i - 1, i - 1] += stiffnesses[i]
        if right_end_fixed:
            K[n - 1, n - 1] += stiffnesses[n]
        scale = mp.diag([1 / mp.sqrt(m) for m in masses])
        eigenvalues = mp.eigsy(scale * K * scale, eigvals_only=True)
        return sorted(mp.sqrt(v) / (2 * mp.pi) for v in eigenvalues)


@pytest.mark.parametrize("masses, stiffnesses", [
    pytest.param([2.0, 3.0, 1.5], [1e3, 1e9, 1e13, 1e3], id="stiffness contrasts 1e6 and 1e10"),
    pytest.param([1.0, 1e6, 1.0], [1e4, 2e4, 3e4, 1e4], id="mass ratios 1e6"),
])
def test_contrasts_in_one_model(masses, stiffnesses):
    reference = np.repeat(chain_reference_hz(masses, stiffnesses, True), 3)
    got = natural_frequencies(chain_along_x(masses, stiffnesses, True), count=9)
    np.testing.assert_allclose(got.frequencies_hz, reference, rtol=1e-9)


def test_25_digits_in_mixed_units():
    """Launcher-like magnitudes (tonnes, 1e5–1e8 N/m): Ū_all mixes newtons and metres, so
    a determinant that calls a pivot below ‖Ū‖·eps zero (mpmath.det did) stops the
    refinement early; these came back right to only 18–20 digits."""
    masses, stiffnesses = [2000.0, 500.0, 8000.0], [3e6, 1e8, 5e5, 2e7]
    got = natural_frequencies(chain_along_x(masses, stiffnesses, True), count=9, digits=25)
    assert got.precision == "mpmath:25"
    with mp.workdps(50):
        want = [f for f in chain_reference_mp(masses, stiffnesses, True) for _ in range(3)]
        assert max(abs(mp.mpf(text) / f - 1) for text, f in zip(got.frequencies_text, want)) < mp.mpf(10) ** -24


def test_chain_of_2000_rigid_bodies_and_springs():
    """Uniform fixed–free chain: ω_n = 2√(k/m) sin((2n−1)π / (2(2N+1)))."""
    n, m, k = 2000, 1.0, 1e6
    got = natural_frequencies(chain_along_x([m] * n, [k] * n), count=12)
    modes = np.arange(1, 5)
    omega = 2 * np.sqrt(k / m) * np.sin((2 * modes - 1) * np.pi / (2 * (2 * n + 1)))
    np.testing.assert_allclose(got.frequencies_hz, np.repeat(omega / (2 * np.pi), 3), rtol=1e-9)


def cantilever_bending_rad(beam, modes: int, dps: int = 40, exact: bool = False) -> list[list]:
    """The lowest ``modes`` bending frequencies (rad/s) of a fixed–free ``beam`` in its
    z and y planes: cos λ + 1/cosh λ = 0 solved in mpmath at ``dps`` digits; floats,
    or mpf values with ``exact``."""
    with mp.workdps(dps):
        starts = [1.875, 4.694] + [(2 * n - 1) * mp.pi / 2 for n in range(3, modes + 1)]
        lambdas = [mp.findroot(lambda x: mp.cos(x) + 1 / mp.cosh(x), x0) for x0 in starts]
        value = (lambda x: +x) if exact else float
        return [[value(lam**2 * mp.sqrt(mp.mpf(beam.E) * mp.mpf(I) / (mp.mpf(beam.rho) * mp.mpf(beam.A)
                                                                      * mp.mpf(beam.length) ** 4)))
                 for lam in lambdas] for I in (beam.Iz, beam.Iy)]


def test_cantilever_first_40_bending_modes_per_plane():
    """βL up to ≈ 124: the frequency equation cos λ + 1/cosh λ = 0 in mpmath."""
    model = single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=4.5e-7, axial=False, torsion=False)
    z_plane, y_plane = ([w / (2 * np.pi) for w in plane] for plane in cantilever_bending_rad(model.beams[0], 40))
    got = natural_frequencies(model, fmax=z_plane[-1] * (1 + 1e-9), count=None)
    want = np.sort([f for f in z_plane + y_plane if f <= z_plane[-1] * (1 + 1e-9)])
    assert len(got.frequencies_hz) == len(want) >= 80 - 40 + 1
    np.testing.assert_allclose(got.frequencies_hz, want, rtol=1e-9)


def test_40th_double_bending_root_to_20_digits():
    """A round cantilever's first 40 double roots at digits=20 (βL up to ≈ 124: the
    beam functions grow by 54 digits, covered by the mpmath path's guard digits),
    against cos λ + 1/cosh λ = 0 solved at 60 digits."""
    model = single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=2e-7, axial=False, torsion=False)
    got = natural_frequencies(model, count=80, digits=20)
    with mp.workdps(60):
        plane, _ = cantilever_bending_rad(model.beams[0], 40, dps=60, exact=True)
        want = [omega / (2 * mp.pi) for omega in plane for _ in range(2)]
        assert max(abs(mp.mpf(text) / f - 1) for text, f in zip(got.frequencies_text, want)) < mp.mpf(10) ** -19


def test_a_missing_close_pair_is_recovered_by_deflated_counts():
    """Two bending planes (Iz : Iy = 1 : 1.6) give pairs of roots 1–2 % apart, inside
    one step of the scan (2.9 %). With the closed-form roots given as found, less two
    such pairs, bisection on counts of det with the found roots divided out and a
    dense scan of the deflated det find all four again."""
    model, exact, upper = two_plane_cantilever_roots()
    gaps = np.diff(exact) / exact[1:]
    pairs = np.argsort(gaps)[:2]  # the two closest pairs
    assert np.all(gaps[pairs] < 0.02)
    dropped = {i for p in pairs for i in (p, p + 1)}
    _, finder, _ = frequency_finder(model)
    recovered, cap = finder._recovered([w for i, w in enumerate(exact) if i not in dropped], upper)
    np.testing.assert_allclose([w for w in recovered if w < upper], exact, rtol=1e-10)
    assert cap == upper


def two_plane_cantilever_roots(modes: int = 12):
    """A cantilever bending in two planes (Iz : Iy = 1 : 1.6): its model and every
    bending root (rad/s) below the last complete pair, from the closed form."""
    model = single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=3.2e-7, axial=False, torsion=False)
    planes = cantilever_bending_rad(model.beams[0], modes)
    upper = 0.99 * min(plane[-1] for plane in planes)
    return model, sorted(w for plane in planes for w in plane if w < upper), upper


def test_recovery_for_a_count_stops_above_the_count_th_root():
    """Asked for the lowest k roots with the two highest missing: bisection does not
    chase roots above the k-th; the closing count is capped between them."""
    model, exact, upper = two_plane_cantilever_roots()
    k = len(exact) - 2
    _, finder, _ = frequency_finder(model)
    recovered, cap = finder._recovered(exact[:k], upper, count=k)
    assert recovered == exact[:k]
    assert exact[k - 1] < cap <= exact[k]
    assert finder._confirmed(recovered, k, cap=cap) == exact[:k]


def test_spurious_doubles_and_missing_roots_are_both_repaired():
    """Two roots read as double (a spurious near-zero offset of the pencil, as MLRS
    showed above 400 Hz) and two others missing, so the count is met by the wrong
    roots: the doubles are recounted first, and the two missing ones are then
    recovered below the highest root found although fewer than ``count`` remain."""
    model, exact, _ = two_plane_cantilever_roots()
    k = len(exact) - 2
    found = sorted(exact[:2] + [exact[2]] * 2 + exact[4:6] + [exact[6]] * 2 + exact[8:k])
    assert len(found) == k
    _, finder, _ = frequency_finder(model)
    repaired = finder._closed(found, k, None, [(np.zeros(0),) * 3])
    np.testing.assert_allclose(repaired, exact[:k], rtol=1e-10)


def scan_with_shared_steps():
    """The two-plane cantilever's finder, exact roots, one fast-path scan (grid, sign,
    log|det|) below its top, and the indices i whose roots i and i + 1 share a step
    of that scan (det has no sign change there)."""
    model, exact, upper = two_plane_cantilever_roots()
    _, finder, _ = frequency_finder(model)
    grid = finder._quick_grid(0.5 * exact[0], upper)
    shared = [i for i in range(len(exact) - 1)
              if np.searchsorted(grid, exact[i]) == np.searchsorted(grid, exact[i + 1])]
    assert shared
    return finder, exact, (grid, *finder.log_det(grid)), shared


def test_a_root_sharing_a_scan_step_with_a_found_one_is_seen_in_the_stored_scan():
    """The scan's own values, divided by the found roots, change sign at a missing
    member of a close pair (no sign change of det across the step holding both)."""
    finder, exact, scan, shared = scan_with_shared_steps()
    dropped = {i + 1 for i in shared}
    rescanned = finder._rescanned([w for i, w in enumerate(exact) if i not in dropped], [scan])
    np.testing.assert_allclose(rescanned, exact, rtol=1e-10)


def test_both_members_of_a_pair_in_one_scan_step_come_back_from_the_stored_scan():
    """With neither member found, the first pass over the stored scan finds one (a quiet
    minimum of the deflated det); the next pass, with that one divided out too, sees
    the other's sign change."""
    finder, exact, scan, shared = scan_with_shared_steps()
    for i in shared:
        rescanned = finder._rescanned([w for j, w in enumerate(exact) if j not in (i, i + 1)], [scan])
        np.testing.assert_allclose(rescanned, exact, rtol=1e-10)


def test_a_coarse_scan_still_finds_every_root_in_the_fast_path(monkeypatch):
    """A scan of 4 points per octave (a step of 19 %, holding both members of several
    pairs; refused from users, set here to exercise the repairs on many roots at once):
    the fast path's repairs find every root, without the segment search."""
    model, exact, _ = two_plane_cantilever_roots()
    _, finder, _ = frequency_finder(model)
    finder.points_per_octave = 4
    monkeypatch.setattr(finder, "_search", lambda *args: pytest.fail("fell back to the segment search"))
    np.testing.assert_allclose(finder.find(len(exact), None).roots, exact, rtol=1e-10)


def nafems_fv2_double_cross():
    """NAFEMS FV2: eight 5 m arms pinned at their ends, 0.125 m square section, in plane.

    The reference values are those of inextensible arms (the 7-fold roots are
    arms clamped at the centre, pinned outside: 3.9266² / (2π L²) √(EI/ρA));
    so the arms are axially rigid, and out-of-plane bending is made 1e6 times
    stiffer and torsion rigid so that only in-plane modes fall below 60 Hz.
    Rigid arms pinned at both ends leave axial forces statically
    indeterminate: the solver has to release them.
    """
    side = 0.125
    I = side**4 / 12
    material = {"E": 200e9, "G": 80e9, "rho": 8000.0}
    points = {"c": np.zeros(3)}
    beams = []
    for i in range(8):
        angle = i * np.pi / 4
        points[f"e{i}"] = 5.0 * np.array([np.cos(angle), np.sin(angle), 0.0])
        beams.append(make_beam(f"arm{i}", "c", f"e{i}", points, A=side**2, Iz=I, Iy=I * 1e6,
                               J=2.25 * side**4 / 16, material=material, axial=False, torsion=False))
    boundary = {f"e{i}": fixed("x", "y", "z") for i in range(8)}
    return Model("NAFEMS FV2", points, beams=tuple(beams), boundary=boundary)


def test_nafems_fv2_root_of_multiplicity_seven():
    """In-plane closed form 11.336, 17.709 (×7), 45.345, 57.390 (×7) Hz (NAFEMS FV2)."""
    got = natural_frequencies(nafems_fv2_double_cross(), fmax=60.0, count=None)
    want = np.array([11.336] + [17.709] * 7 + [45.345] + [57.390] * 7)
    assert got.ubar_order == 48
    np.testing.assert_allclose(got.frequencies_hz, want, rtol=5e-5)
    sevens = got.frequencies_hz[1:8]
    assert np.ptp(sevens) < 1e-9 * sevens[0]


def test_near_zero_elastic_modes_next_to_rigid_body_modes():
    """Two free bodies on a very soft spring at their common mass centre.

    Relative translation: ω² = k (1/m1 + 1/m2); relative rotation about axis i:
    ω² = k_r (1/J1_i + 1/J2_i). Six rigid-body modes at zero.
    """
    m1, m2, k, kr = 2.0, 3.0, 1e-4, 2e-4
    J1, J2 = np.array([1.0, 2.0, 3.0]), np.array([1.5, 2.5, 3.5])  # real bodies: J3 <= J1 + J2
    points = {"p": np.zeros(3), "q": np.zeros(3)}
    model = Model("soft pair", points,
                  rigids=(make_rigid("one", ["p"], m1, [0, 0, 0], J1),
                          make_rigid("two", ["q"], m2, [0, 0, 0], J2)),
                  springs=(make_spring("soft", "p", "q", [k, k, k, kr, kr, kr]),))
    got = natural_frequencies(model, count=6)
    want = np.sort(np.r_[[np.sqrt(k * (1 / m1 + 1 / m2))] * 3, np.sqrt(kr * (1 / J1 + 1 / J2))]) / (2 * np.pi)
    assert got.rigid_body_modes == 6
    np.testing.assert_allclose(got.frequencies_hz, want, rtol=1e-9)


@pytest.mark.parametrize("Iy", [1e-12, 1e-14, 1e-16, 1e-18, 1e-20, 1e-22, 1e-24])
def test_thin_strip_cantilever_gives_fe_frequencies_through_the_command(Iy, tmp_path, capsys):
    """The bundled steel cantilever with Iy from 1e-12 down to 1e-24 m⁴ (Iz stays 2e-7):
    ``linmstmm freqs`` gives the FE route's frequencies (its first, 1.7e-7 Hz at
    1e-24, is 1e6 times below the other plane's). Iy = 1e-20 returned four frequencies
    around 2e-4 Hz for FE's 1.5e-6 … 7e-5 Hz, without a word, and then was refused
    while the search's floor was 1e-3 rad/s whatever the model; it is now a multiple
    of the model's own frequency scale."""
    import dataclasses
    import json

    from random_models import to_toml

    from linmstmm.cli import main
    from linmstmm.fe import fe_frequencies
    from linmstmm.model import load_model

    bundled = load_model("models/cantilever_tip_mass.toml")
    model = dataclasses.replace(bundled, beams=(dataclasses.replace(bundled.beams[0], Iy=Iy),))
    path = tmp_path / "strip.toml"
    path.write_text(to_toml(model))
    fe = fe_frequencies(load_model(path), count=6)
    status = main(["freqs", str(path), "--count", "6", "--json"])
    out, err = capsys.readouterr()
    assert status == 0 and not err, err
    found = json.loads(out)["frequencies_hz"]
    np.testing.assert_allclose(found, fe.frequencies_hz, rtol=max(1e-9, 3 * float(fe.error_estimate.max())))
