"""Modal response and FRF by MSTMM modes against the FE route's M, C, K solved directly.

The model is a tree with a closed loop made of rigid bodies and springs
only, so the FE route has exactly the model's 18 DOFs (no mesh) and the
modal sum with all 18 modes must reproduce the direct solution. The direct
solutions are independent of the modes: the state-space matrix exponential
for the impulse and the step, and a linear solve for the harmonic response.

The static correction is checked on the bundled held models: a damped step
response with a truncated modal sum must settle on the FE route's static
solution K⁻¹ f (a sparse direct solve on its default mesh).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse.linalg
from builders import fixed, make_rigid, make_spring, single_beam_model

from linmstmm.fe import assemble, static_displacements
from linmstmm.model import Model, load_model
from linmstmm.modes import mode_shapes
from linmstmm.response import LoadCase, PointLoad, frf, impulse, modal_response, respond, step

ROOT = Path(__file__).resolve().parents[1]

DAMPING = (0.3, 2e-4)
TIMES = np.linspace(0.0, 1.5, 301)


def looped_tree() -> Model:
    """ground–k0–base(3 ports)=k1,k2=>top (a loop through two springs); top–k3–pod (tip body)."""
    points = {"g": np.zeros(3), "b0": np.zeros(3),
              "b1": np.array([0.4, 0.0, 0.5]), "t1": np.array([0.4, 0.0, 0.5]),
              "b2": np.array([-0.4, 0.1, 0.5]), "t2": np.array([-0.4, 0.1, 0.5]),
              "t3": np.array([0.0, 0.3, 1.0]), "p3": np.array([0.0, 0.3, 1.0])}
    axes = scipy.linalg.expm(np.array([[0, -0.3, 0.2], [0.3, 0, -0.1], [-0.2, 0.1, 0]]))
    return Model(
        "looped tree", points,
        rigids=(make_rigid("base", ["b0", "b1", "b2"], 30.0, [0.0, 0.05, 0.2],
                           [[2.0, 0.1, 0.0], [0.1, 2.5, -0.2], [0.0, -0.2, 1.5]]),
                make_rigid("top", ["t1", "t2", "t3"], 12.0, [0.0, 0.1, 0.6], [0.8, 0.6, 1.1]),
                make_rigid("pod", ["p3"], 4.0, [0.05, 0.35, 1.1], [0.05, 0.07, 0.06])),
        springs=(make_spring("k0", "g", "b0", [4e5, 5e5, 8e5, 6e4, 7e4, 5e4]),
                 make_spring("k1", "b1", "t1", [2e5, 3e5, 1e5, 4e3, 5e3, 6e3], axes),
                 make_spring("k2", "b2", "t2", [1.5e5, 2e5, 2.5e5, 3e3, 2e3, 4e3]),
                 make_spring("k3", "t3", "p3", [5e4, 6e4, 7e4, 9e2, 8e2, 7e2], axes.T)),
        boundary={"g": fixed()})


@pytest.fixture(scope="module")
def setting():
    model = looped_tree()
    fe = assemble(model)
    assert fe.n_dof == 18
    modes = mode_shapes(model, count=18)
    M, K = fe.M.toarray(), fe.K.toarray()
    return model, fe, modes, M, K, DAMPING[0] * M + DAMPING[1] * K


def fe_load(fe, point, vector):
    full = np.zeros(fe.n_full)
    full[fe.dof_index.point(point)] = vector
    return fe.T.T @ full


def fe_at(fe, point, q):
    """(..., 6) motion of ``point`` from reduced vectors q (..., n_dof)."""
    return (fe.T @ q.T).T[..., fe.dof_index.point(point)]


def relative_l2(got, want):
    return np.linalg.norm(got - want) / np.linalg.norm(want)


def state_space(M, C, K):
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]]), Minv


LOAD_VECTOR = np.array([120.0, -80.0, 200.0, 5.0, -3.0, 2.0])


@pytest.mark.parametrize("kind", ["impulse", "step"])
def test_modal_response_equals_direct_state_space_solution(setting, kind):
    model, fe, modes, M, K, C = setting
    assert modes.omega.size - modes.rigid_body_modes == 18
    A, Minv = state_space(M, C, K)
    f = fe_load(fe, "t3", LOAD_VECTOR)
    n = M.shape[0]
    if kind == "impulse":
        start = np.r_[np.zeros(n), Minv @ f]
        states = np.array([scipy.linalg.expm(A * t) @ start for t in TIMES])
        function = impulse(0.0)
    else:  # y(t) = A⁻¹ (e^{At} − I) B for a unit step
        B = np.r_[np.zeros(n), Minv @ f]
        states = np.array([np.linalg.solve(A, (scipy.linalg.expm(A * t) - np.eye(2 * n)) @ B)
                           for t in TIMES])
        function = step(0.0)
    load = PointLoad("t3", LOAD_VECTOR[:3], LOAD_VECTOR[3:], function)
    result = modal_response(modes, [load], TIMES, ["b1", "p3"], DAMPING)
    for i, point in enumerate(["b1", "p3"]):
        assert relative_l2(result.displacement[:, i], fe_at(fe, point, states[:, :n])) < 1e-8
        assert relative_l2(result.velocity[:, i], fe_at(fe, point, states[:, n:])) < 1e-8


def test_frf_equals_direct_harmonic_solve(setting):
    model, fe, modes, M, K, C = setting
    frequencies = np.linspace(1.0, 60.0, 120)
    result = frf(modes, "t1", LOAD_VECTOR, frequencies, ["p3", "b2"], DAMPING)
    f = fe_load(fe, "t1", LOAD_VECTOR)
    for Hz, H in zip(frequencies, result.receptance):
        W = 2 * np.pi * Hz
        q = np.linalg.solve(K - W**2 * M + 1j * W * C, f)
        for i, point in enumerate(["p3", "b2"]):
            want = fe_at(fe, point, q)
            assert np.abs(H[i] - want).max() < 1e-8 * np.abs(want).max()


# --- static correction ------------------------------------------------------------

HELD_MODELS = {  # model, loaded point, [force N, moment N m], seconds to settle at ζ = 0.3
    "cantilever": ("models/cantilever_tip_mass.toml", "tip", [30.0, -40.0, -100.0, 5.0, 8.0, -6.0], 2.0),
    "launcher": ("models/mlrs/mlrs.toml", "tube_rear", [-3939.231, 500.0, -694.5927, 100.0, -200.0, 50.0],
                 6.0),
}


def fe_static(model, point, vector):
    """point -> (6,) K⁻¹ f by a sparse direct solve on the FE route's default mesh."""
    fe = assemble(model)
    q = scipy.sparse.linalg.spsolve(fe.K.tocsc(), fe_load(fe, point, vector))
    return {p: fe_at(fe, p, q) for p in model.points}


@pytest.mark.parametrize("name", HELD_MODELS)
def test_damped_step_settles_on_the_static_solution(name):
    """Long-time mean of a step response (10 modes, ζ = 0.3) = K⁻¹ f to 1e-6 with the
    static correction; the truncated modal sum alone is further off than that."""
    file, point, vector, settle = HELD_MODELS[name]
    model = load_model(ROOT / file)
    vector = np.array(vector)
    case = LoadCase((PointLoad(point, vector[:3], vector[3:], step(0.01)),),
                    np.linspace(0.0, settle, 2001), tuple(model.points), 10)
    want = fe_static(model, point, vector)
    scale = max(np.abs(w).max() for w in want.values())
    for corrected in (True, False):
        result = respond(model, case, damping_ratio=0.3, static_correction=corrected)
        assert result.static_correction is corrected and result.elastic_modes >= 10
        late = result.displacement[result.times > 0.8 * settle].mean(axis=0)
        error = max(np.abs(late[i] - want[p]).max() for i, p in enumerate(result.points)) / scale
        assert bool(error < 1e-6) == corrected, (corrected, error)


def test_static_solution_of_the_cantilever_is_the_closed_form():
    """Tip force F: deflection F L³ / (3 E I) and slope F L² / (2 E I), on one element."""
    model = load_model(ROOT / HELD_MODELS["cantilever"][0])
    beam = model.beams[0]
    got = static_displacements(model, [("tip", [0.0, 0.0, -100.0, 0.0, 0.0, 0.0])], ["tip"])[0, 0]
    EI = beam.E * beam.Iy
    np.testing.assert_allclose(got[[2, 4]], [-100.0 * beam.length**3 / (3 * EI), 100.0 * beam.length**2 / (2 * EI)],
                               rtol=1e-12)


def test_free_floating_model_gets_no_static_correction_and_says_so():
    model = single_beam_model()
    case = LoadCase((PointLoad("b", np.array([0.0, 0.0, 10.0]), np.zeros(3), step()),),
                    np.linspace(0.0, 0.1, 11), ("a", "b"), 4)
    result = respond(model, case)
    assert not result.static_correction and "6 rigid-body modes" in result.note
