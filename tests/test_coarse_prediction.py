"""The coarse FE pencil kept in standard form (CoarsePencil.reduced): the predictions it
gives are, to the bit, the eigenvalues scipy's generalized eigensolver (sygvx) finds
on the pencil itself, so keeping the form changes no prediction and no search path;
where the mass matrix is singular there is no standard form, and QZ predicts."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from linmstmm.coarse_prediction import coarse_modes, coarse_pencil, coarse_predictions
from linmstmm.standard_eigen import BISECTED, Bisection, lowest_eigenpairs
from linmstmm.model import load_model
from random_models import KINDS, random_model

MODELS = {"launcher": lambda: load_model("models/mlrs/mlrs.toml"),
          "launcher 2": lambda: load_model("models/launcher2/launcher2.toml"),
          "cantilever": lambda: load_model("models/cantilever_tip_mass.toml"),
          **{f"{kind} {seed}": (lambda kind=kind, seed=seed: random_model(kind, seed))
             for kind in KINDS for seed in range(3)}}


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("count", [10, 30])
def test_predictions_from_the_kept_standard_form_are_the_generalized_eigenvalues(name, count):
    """Where M is positive definite, the predictions are sygvx's eigenvalues on (K, M)
    to the bit; where it is not (sygvx refuses), there is no standard form."""
    model = MODELS[name]()
    pencil = coarse_pencil(model, 2)
    n = pencil.K.shape[0]
    wanted = min(count + pencil.rigid_body_modes, n) - 1
    try:
        generalized = scipy.linalg.eigh(pencil.K, pencil.M, eigvals_only=True, subset_by_index=[0, wanted])
    except np.linalg.LinAlgError:  # massless unknowns
        assert pencil.reduced is None
        return
    expected = np.sqrt(np.maximum(np.sort(generalized)[pencil.rigid_body_modes:][:count], 0.0))
    assert pencil.reduced is not None
    assert np.array_equal(coarse_predictions(model, count, 2), expected)


def test_both_kinds_of_mass_matrix_are_among_the_models():
    """The test above sees positive definite and singular mass matrices alike."""
    kinds = {coarse_pencil(build(), 2).reduced is None for build in MODELS.values()}
    assert kinds == {True, False}


@pytest.mark.parametrize("name", ["launcher", "launcher 2", "cantilever"])
@pytest.mark.parametrize("count", [1, 13, BISECTED, BISECTED + 1, 60])
def test_the_standard_form_is_solved_as_scipy_eigh_solves_it(name, count):
    """LAPACK's syevx (bisection, in its steps) and syev (all at once), called directly,
    give scipy.linalg.eigh's eigenvalues of the kept standard form to the bit."""
    reduced = coarse_pencil(MODELS[name](), 2).reduced
    count = min(count, reduced.shape[0])
    if count > BISECTED:
        expected = scipy.linalg.eigh(reduced, eigvals_only=True, driver="ev", lower=True)
    else:
        expected = scipy.linalg.eigh(reduced, eigvals_only=True, subset_by_index=[0, count - 1], driver="evx",
                                     lower=True)
    assert np.array_equal(lowest_eigenpairs(reduced, count)[0], expected)


@pytest.mark.parametrize("name", ["launcher", "launcher 2"])
def test_beyond_bisection_the_vectors_come_by_divide_and_conquer(name):
    """More than BISECTED wanted with their vectors: syevd, scipy.linalg.eigh's "evd"
    driver, its eigenvalues to the bit, and orthonormal eigenvectors of the kept
    standard form (residuals at rounding of its norm)."""
    reduced = coarse_pencil(MODELS[name](), 2).reduced
    values, vectors, _ = lowest_eigenpairs(reduced, BISECTED + 1, vectors=True)
    expected, expected_vectors = scipy.linalg.eigh(reduced, driver="evd", lower=True)
    assert np.array_equal(values, expected) and np.array_equal(vectors, expected_vectors)
    full = np.tril(reduced) + np.tril(reduced, -1).T
    np.testing.assert_allclose(vectors.T @ vectors, np.eye(vectors.shape[1]), rtol=0, atol=1e-13)
    assert np.max(np.abs(full @ vectors - vectors * values)) <= 1e-13 * np.abs(values).max()


@pytest.mark.parametrize("name", ["launcher", "launcher 2", "cantilever"])
@pytest.mark.parametrize("count", [1, 13, BISECTED])
def test_syevx_in_its_steps_gives_eighs_vectors_now_or_later(name, count):
    """Up to BISECTED, the eigenvectors from syevx's steps (stein, then ormtr's ormqr)
    are scipy.linalg.eigh(driver="evx")'s to the bit, asked for with the eigenvalues or
    after them."""
    reduced = coarse_pencil(MODELS[name](), 2).reduced
    count = min(count, reduced.shape[0] - 1)  # all of them: syevx itself
    expected, expected_vectors = scipy.linalg.eigh(reduced, subset_by_index=[0, count - 1], driver="evx", lower=True)
    values, vectors, _ = lowest_eigenpairs(reduced, count, vectors=True)
    assert np.array_equal(values, expected) and np.array_equal(vectors, expected_vectors)
    later = Bisection(reduced, count)
    assert np.array_equal(later.values, expected) and np.array_equal(later.vectors(), expected_vectors)


@pytest.mark.parametrize("name", ["launcher", "cantilever", "floating_tree 0", "loops 1", "ring 0"])
def test_coarse_modes_made_later_are_those_made_at_once(name):
    """The modes at the nodes of a prediction made without them come later from its own
    bisection, the same to the bit as made with the frequencies, some rows or all; so
    too where the pencil has rigid-body modes, whose vectors the elastic ones are made
    beside (without them, stein had made elastic modes that were rigid-body motions)."""
    model = MODELS[name]()
    assert name in ("launcher", "cantilever") or coarse_pencil(model, 2).rigid_body_modes > 0
    at_once = coarse_modes(model, 8, 2, nodal=True)
    first = coarse_modes(model, 8, 2, nodal=False)
    assert first.nodal is None and np.array_equal(first.values, at_once.values)
    assert np.array_equal(first.later(), at_once.nodal)
    rows = np.array([5, 1, 6])
    assert np.array_equal(first.later(rows), at_once.nodal[rows])


@pytest.mark.parametrize("seed", [152, 25])
def test_eigenvalues_within_rounding_of_zero_are_zero_by_either_bisection(seed):
    """Varied models whose coarse forms span 1.8e21 (seed 152) and 5e17 (seed 25): their
    lowest eigenvalues are rounding of the largest (seed 152, eigvalsh: -1.5e5 to -284
    against ε ‖C‖ = 4e5, where its lowest root is 0.16 (rad/s)²), their signs arbitrary.
    Both bisections give the lowest as zero, so neither passes rounding off as a
    prediction: bracketed to 1e-7, they had come out at +8.3e3 and the search took
    31,383 evaluations of det instead of 469 (seed 25: 6,166 instead of 475). The values
    a hundred times that level or more agree within the accuracy asked and the level's
    hundredth."""
    from linmstmm.determinant import load_kernels
    from varied_models import varied_model

    load_kernels()  # the compiled bracketing is taken only where the kernels are loaded
    model = varied_model(seed)[0]
    level = coarse_pencil(model, 2).rounding_level
    exact = coarse_modes(model, 20, 2, nodal=False).values
    bracketed = coarse_modes(model, 20, 2, nodal=True, later=True, accuracy=1e-7).values
    assert exact[0] == 0 and bracketed[0] == 0
    clear = exact ** 2 > 100 * level
    assert clear.sum() >= 5
    assert np.all(np.abs(bracketed[clear] ** 2 / exact[clear] ** 2 - 1) <= 1e-7 + 0.01)
