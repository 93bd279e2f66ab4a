"""Statically indeterminate unknowns found on the compiled program's plain Ū_all.

:meth:`~linmstmm.determinant.CompiledDeterminant.plain_matrix` replays the
compiled program with its orthonormalisations only laid out: it must be
:meth:`~linmstmm.deduction.Deduction.matrix` (the numpy carry, ``stable=False``)
to rounding. :func:`~linmstmm.nullspace.release_indeterminate` screens its probes
with it and must release exactly the unknowns and rows the numpy carry alone
releases, and still refuse a null space that moves with ω.
"""
from __future__ import annotations

import mpmath
import numpy as np
import pytest
from builders import BUNDLED_MODELS
from random_models import KINDS, random_model
from test_extremes import nafems_fv2_double_cross
from test_joints import beam_on_joint, four_bar, hinged_chain, pinned_bars, sliding_carts, with_random_joints
from varied_models import varied_model

from linmstmm.deduction import Deduction
from linmstmm.determinant import CompiledDeterminant
from linmstmm.model import load_model
from linmstmm.nullspace import PROBES, characteristic_frequencies, equilibration, release_indeterminate
from linmstmm.numeric import power_of_two_scale
from linmstmm.solve import natural_frequencies
from linmstmm.topology import build_topology

#: Models of the test suite in which something is released (found by the numpy carry):
#: inf springs closing loops, pinned axially rigid arms, joints beside rigid springs.
RELEASING = {
    "varied 24": lambda: varied_model(24)[0],
    "varied 71": lambda: varied_model(71)[0],
    "varied 358 (two)": lambda: varied_model(358)[0],
    "varied 522": lambda: varied_model(522)[0],
    "random tree 9": lambda: random_model("tree", 9),
    "random loops 25": lambda: random_model("loops", 25),
    "random loops 46": lambda: random_model("loops", 46),
    "random floating loops 42": lambda: random_model("floating_loops", 42),
    "random tree 19 with joints": lambda: with_random_joints(random_model("tree", 19), np.random.default_rng(1019)),
    "NAFEMS FV2 (six)": nafems_fv2_double_cross,
}
JOINTS = {"four bar": four_bar, "hinged chain": hinged_chain, "pinned bars": pinned_bars,
          "sliding carts": sliding_carts, "ball joint": lambda: beam_on_joint(["rx", "ry", "rz"])}


def released(model, screened: bool):
    """(count, released columns, released rows) of ``model``, its probes screened by the
    compiled plain Ū_all or read by the numpy carry alone."""
    deduction = Deduction(build_topology(model))
    screen = CompiledDeterminant(deduction).plain_matrix if screened else None
    count = release_indeterminate(deduction, screen=screen)
    return count, deduction.released_columns.tolist(), deduction.released_rows.tolist()


@pytest.mark.parametrize("make", list(RELEASING.values()), ids=list(RELEASING))
def test_the_screened_probes_release_the_numpy_carrys_unknowns(make):
    model = make()
    numpy_release = released(model, screened=False)
    assert numpy_release[0] >= 1
    assert released(model, screened=True) == numpy_release


@pytest.mark.parametrize("make", [lambda path=path: load_model(path) for path in BUNDLED_MODELS]
                         + list(JOINTS.values()), ids=[p.name for p in BUNDLED_MODELS] + list(JOINTS))
def test_bundled_and_joint_models_release_the_same(make):
    model = make()
    assert released(model, screened=True) == released(model, screened=False)


def test_hundreds_of_random_models_release_the_same():
    """320 varied models (the extremes: slender beams, Iy/Iz to 1e12, other units) and 40
    random models of each kind, 14 of which release something."""
    models = [varied_model(seed)[0] for seed in range(320)]
    models += [random_model(kind, seed) for kind in KINDS for seed in range(40)]
    releasing = 0
    for model in models:
        numpy_release = released(model, screened=False)
        assert released(model, screened=True) == numpy_release, model.name
        releasing += numpy_release[0] > 0
    assert releasing >= 10


def moving_null_vector(matrix, scale):
    """``matrix`` (frequencies (n,) -> (n, N, N)) with its first column made ω / scale times
    its second: singular at every ω, its null vector moving with ω."""
    def moved(omega):
        samples = np.array(matrix(omega))
        samples[:, :, 0] = samples[:, :, 1] * (np.asarray(omega) / scale)[:, None]
        return samples
    return moved


@pytest.mark.parametrize("screened", [False, True])
def test_a_null_space_that_moves_with_frequency_is_still_refused(screened, monkeypatch):
    """No model of the suite has one (a conservative model's constant null vectors are
    redundant constraints or massless motions); one is made by mixing two columns with
    a weight ω / scale, in the numpy carry and in the screen alike."""
    deduction = Deduction(build_topology(random_model("loops", 25)))
    scale = min(characteristic_frequencies(deduction.topology))
    screen = moving_null_vector(CompiledDeterminant(deduction).plain_matrix, scale) if screened else None
    monkeypatch.setattr(deduction, "matrix", moving_null_vector(deduction.matrix, scale))
    with pytest.raises(RuntimeError, match="the model has a mechanism"):
        release_indeterminate(deduction, screen=screen)


def plain_cases():
    models = [random_model(kind, seed) for kind in KINDS for seed in range(8)]
    models += [with_random_joints(random_model(kind, seed), np.random.default_rng(1000 + seed))
               for kind in KINDS for seed in range(3)]
    return models + [load_model(path) for path in BUNDLED_MODELS]


def test_the_plain_matrix_is_the_numpy_carrys():
    """At the probes and up to 3000 times the model's scale, balanced as the release
    balances it (by the numpy matrix at the first probe), each entry within 1e-12 of
    the largest; where a carry loses more to cancellation (a random floating loop,
    2.2e-11 apart at 0.07 times its scale), the compiled matrix must be as close to the
    exact one (mpmath, 40 digits) as the numpy one is, within a factor 2."""
    for model in plain_cases():
        deduction = Deduction(build_topology(model))
        plain = CompiledDeterminant(deduction).plain_matrix
        omegas = np.r_[PROBES, 3.0, 30.0, 300.0, 3000.0] * min(characteristic_frequencies(deduction.topology))
        reference, compiled = deduction.matrix(omegas), plain(omegas)
        rows, cols = equilibration(reference[0])
        for omega, a, b in zip(omegas, rows[:, None] * reference * cols, rows[:, None] * compiled * cols):
            largest = np.abs(a).max()
            if np.abs(b - a).max() <= 1e-12 * largest:
                continue
            with mpmath.workdps(40):
                exact = np.array(deduction.matrix(np.array([mpmath.mpf(omega)], dtype=object))[0].tolist(), float)
            exact = rows[:, None] * exact * cols
            assert np.abs(b - exact).max() <= 2 * np.abs(a - exact).max(), (model.name, omega)


def test_a_program_compiled_before_a_release_is_not_used_after_it():
    """The program carries the unknowns it was compiled for: after a release it must be
    compiled anew, and the solve does so (the same frequencies as the numpy engine)."""
    model = random_model("loops", 25)
    deduction = Deduction(build_topology(model))
    early = CompiledDeterminant(deduction)
    assert release_indeterminate(deduction, screen=early.plain_matrix) == 1
    with pytest.raises(RuntimeError, match="compile it anew"):
        early.log_det(np.array([10.0]))
    compiled, reference = (natural_frequencies(model, 6, engine=engine) for engine in ("compiled", "numpy"))
    assert compiled.indeterminate_released == reference.indeterminate_released == 1
    np.testing.assert_allclose(compiled.frequencies_hz, reference.frequencies_hz, rtol=1e-10)


def test_equilibration_is_the_plain_sweeps():
    """The balance equals the plain sweeps it is written for (the rows' part of each
    product formed once per change of rows): the same scales, bit for bit."""
    def plain(matrix, sweeps, start):
        size = np.abs(matrix)
        rows, cols = np.ones(matrix.shape[:-1]) * start[0], np.ones(matrix.shape[:-2] + matrix.shape[-1:]) * start[1]
        for _ in range(sweeps):
            rows *= power_of_two_scale((rows[..., :, None] * size * cols[..., None, :]).max(axis=-1))
            cols *= power_of_two_scale((rows[..., :, None] * size * cols[..., None, :]).max(axis=-2))
        return rows, cols

    rng = np.random.default_rng(7)
    for trial in range(400):
        shape = tuple(rng.integers(1, 30, 2)) if trial % 2 else (3, *rng.integers(1, 30, 2))
        matrix = rng.standard_normal(shape) * 10.0 ** rng.integers(-150, 150, shape) * (rng.random(shape) < 0.6)
        start = (rng.uniform(1e-5, 1e5, shape[:-1]), rng.uniform(1e-5, 1e5, shape[:-2] + shape[-1:]))
        for ours, theirs in zip(equilibration(matrix, start=start), plain(matrix, 4, start)):
            assert np.array_equal(ours, theirs)
    # balanced from the start (|a| within 0.75 and 1.4 of 1): the sweeps stop after the
    # first changes nothing, with the scales of all four
    for trial in range(100):
        matrix = rng.uniform(0.75, 1.4, (5, 7)) * rng.choice([-1.0, 1.0], (5, 7))
        start = (2.0 ** rng.integers(-3, 3, 5), 2.0 ** -rng.integers(-3, 3, 7)) if trial % 2 else (np.ones(5), np.ones(7))
        for ours, theirs in zip(equilibration(matrix, start=start), plain(matrix, 4, start)):
            assert np.array_equal(ours, theirs)


def test_the_bound_never_clears_what_the_svd_would_not():
    """nullspace._well_above (by the Gram matrix, or an inverse above order 93) says a
    matrix's smallest singular value is at least the threshold times its largest only
    where the SVD finds none below it: on matrices of singular values spread over 1 to
    1e-9 (about the threshold and far from it), and it does say so for well conditioned
    ones (or the screen's shortcut would never serve)."""
    from linmstmm.nullspace import _well_above, nullity

    rng = np.random.default_rng(11)
    cleared = 0
    for trial in range(600):
        n = int(rng.integers(2, 70))
        u, _ = np.linalg.qr(rng.standard_normal((n, n)))
        v, _ = np.linalg.qr(rng.standard_normal((n, n)))
        sigma = np.sort(10.0 ** rng.uniform(-rng.uniform(0, 9), 0, n))[::-1]
        matrix = (u * sigma) @ v.T * 10.0 ** rng.integers(-20, 20)
        threshold = 10.0 ** rng.uniform(-9, -3)
        if _well_above(matrix, threshold):
            cleared += 1
            assert nullity(matrix, threshold, (np.ones(n), np.ones(n))) == 0
    assert cleared > 100
    assert not _well_above(np.zeros((4, 4)), 1e-6) and not _well_above(np.diag([1.0, 1e-7]), 1e-6)


@pytest.mark.parametrize("n", [2, 12, 60, 72, 93])
def test_the_gram_test_clears_exactly_what_its_bound_says(n):
    """Up to order 93 at the probes' threshold 1e-6 nullspace._well_above decides by the
    Gram matrix: it clears every matrix whose smallest singular value is 4 times the
    threshold times s = √(‖A‖₁ ‖A‖∞) (twice its margin), and none that the SVD finds a
    singular value below the threshold in, the smallest singular value set at 0.3 to 30
    times the threshold times the largest, over 1e-200 to 1e200 in scale."""
    from linmstmm.nullspace import _well_above, nullity

    rng = np.random.default_rng(n)
    threshold = 1e-6
    for trial in range(40):
        u, _ = np.linalg.qr(rng.standard_normal((n, n)))
        v, _ = np.linalg.qr(rng.standard_normal((n, n)))
        sigma = np.sort(10.0 ** rng.uniform(-3, 0, n))[::-1]
        sigma[-1] = sigma[0] * threshold * 10.0 ** rng.uniform(np.log10(0.3), np.log10(30))
        matrix = (u * sigma) @ v.T * 10.0 ** rng.uniform(-200, 200)
        size = np.abs(matrix)
        s = np.sqrt(size.sum(axis=0).max()) * np.sqrt(size.sum(axis=1).max())
        smallest = np.linalg.svd(matrix, compute_uv=False)[-1]
        if nullity(matrix, threshold, (np.ones(n), np.ones(n))):
            assert not _well_above(matrix, threshold)
        if smallest >= 4 * threshold * s:
            assert _well_above(matrix, threshold)


def test_the_gram_tests_scale_is_an_exact_power_of_two_into_half_one():
    """numeric.scale_into_half_one, which scales the Gram test's matrix: a power of two
    that takes each magnitude into [1/2, 1) exactly, checked in rational arithmetic on
    magnitudes from 1e-300 to 1e300 and on powers of two (which go to 1/2)."""
    from fractions import Fraction

    from linmstmm.numeric import scale_into_half_one

    rng = np.random.default_rng(3)
    powers = [2.0 ** k for k in range(-990, 1000, 37)]
    for magnitude in [*(10.0 ** rng.uniform(-300, 300, 2000)), *powers]:
        scale = Fraction(scale_into_half_one(magnitude))
        assert scale.numerator == 1 or scale.denominator == 1
        assert (scale.numerator * scale.denominator) & (scale.numerator * scale.denominator - 1) == 0
        assert Fraction(1, 2) <= Fraction(magnitude) * scale < 1
        assert magnitude * float(scale) == Fraction(magnitude) * scale
    assert all(p * scale_into_half_one(p) == 0.5 for p in powers)


def test_the_first_probe_alone_releases_what_all_three_did(monkeypatch):
    """The screen decides on the first probe alone (nullspace._screened_probe); before, it
    evaluated all three and sent the probes to the numpy carry where a later one was not
    finite. Both rules release the same columns and rows on 300 random models and 60 with
    joints (those that release something included), and no model has a clearly regular
    first probe whose later probes overflow (the one case the rules could part in)."""
    from linmstmm import nullspace

    def all_three(screen, probe):  # the rule before: every probe finite, the first decides
        samples = screen(probe)
        assert samples.shape[0] == len(PROBES)
        return samples[0] if np.isfinite(samples).all() else np.full_like(samples[0], np.nan)

    models = [random_model(kind, seed) for kind in KINDS for seed in range(60)]
    models += [with_random_joints(random_model(kind, seed), np.random.default_rng(2000 + seed))
               for kind in KINDS for seed in range(12)]
    releasing = screened = 0
    for model in models:
        now = released(model, screened=True)
        with monkeypatch.context() as patch:
            patch.setattr(nullspace, "_screened_probe", all_three)
            assert released(model, screened=True) == now, model.name
        releasing += now[0] > 0
        deduction = Deduction(build_topology(model))
        if not nullspace._statically_determinate(deduction.topology):
            scale = min(characteristic_frequencies(deduction.topology))
            samples = CompiledDeterminant(deduction).plain_matrix(np.asarray(PROBES) * scale)
            start = nullspace.own_units_start(deduction, scale)
            if nullspace._clearly_regular(samples[0], nullspace.SCREEN_MARGIN * nullspace.INDETERMINATE_TOLERANCE,
                                          start):
                screened += 1
                assert np.isfinite(samples).all(), model.name
    assert releasing >= 8 and screened >= 200


def test_the_compiled_balance_is_the_equilibration():
    """_balance_kernels.balanced, which the screen reads, balances as equilibration does
    (the same scales, the balanced matrix bit for bit) and bounds its largest singular
    value by √(‖B‖₁ ‖B‖∞) as _well_above does (to rounding: its sums run in another order)."""
    from linmstmm._balance_kernels import balanced
    from linmstmm.nullspace import EQUILIBRATION_SWEEPS

    rng = np.random.default_rng(17)
    for trial in range(400):
        shape = tuple(rng.integers(1, 70, 2)) if trial % 3 else (int(rng.integers(1, 70)),) * 2
        matrix = rng.standard_normal(shape) * 10.0 ** rng.integers(-150, 150, shape) * (rng.random(shape) < 0.6)
        start = (rng.uniform(1e-5, 1e5, shape[0]), rng.uniform(1e-5, 1e5, shape[1])) if trial % 2 else \
            (np.ones(shape[0]), np.ones(shape[1]))
        rows, cols = equilibration(matrix, start=start)
        ours, bound = balanced(matrix, *start, EQUILIBRATION_SWEEPS)
        assert np.array_equal(ours, rows[:, None] * matrix * cols)
        size = np.abs(ours)
        np.testing.assert_allclose(bound, np.sqrt(size.sum(axis=0).max()) * np.sqrt(size.sum(axis=1).max()),
                                   rtol=1e-13)
