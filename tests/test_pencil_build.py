"""The coarse predictions' pencil, built the cheap way, against the same pencil built
through scipy.sparse, bit for bit.

* On the bundled launchers, the other bundled models and 30 random models (the
  random kinds, and varied models with extreme sections, masses and units), at
  one, two and three elements per beam: the pencil's K, M and scaling equal those
  made from the assembly formed entirely by scipy.sparse (every product forced
  sparse), and its rigid-body count equals the number of rigid-body modes the FE
  route forms (:func:`~linmstmm.fe.assembly.assemble`).
* The same models with the products formed by the compiled kernels
  (:mod:`linmstmm._product_kernels`): the assembly's K and M at one, two and three
  elements per beam, and the Wittrick–Williams counter's springs' stiffness,
  bodies' mass and beams' maps, equal the numpy route's (:mod:`linmstmm.fe.products`, itself
  checked against scipy.sparse) bit for bit; where three beams meet (a position of
  the full mass given three times) the numpy route forms them.
* A body whose inertia Gershgorin's bound cannot clear is looked at only where
  its least principal inertia is not clearly above the negligible one: every
  body the one-call screen passes over is returned unchanged by the full
  per-body check, on tensors whose least principal inertia lies on either side
  of the threshold.
* A model with a negligible mass is assembled on its own node constraints (the
  counter's, kept) given the masses left, the same arrays as the model with that
  mass removed from the start.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from builders import BUNDLED_MODELS, fixed, make_beam, make_rigid
from random_models import KINDS, random_model, random_rotation
from varied_models import varied_model

from linmstmm._product_kernels import pencil_forms, unit_scaled
from linmstmm.coarse_prediction import coarse_pencil
from linmstmm.scaled_pencil import _unit_scaled
from linmstmm.fe import products
from linmstmm.fe.assembly import assemble, assembled
from linmstmm.fe.masses import (
    _body_mass_kept,
    _maybe_negligible,
    _negligible_mass_removed,
)
from linmstmm.fe.node_constraints import kept_node_constraints
from linmstmm.fe.products import small
from linmstmm.fe.sparse import as_scipy, scipy_csr
from linmstmm.model import Model, load_model
from linmstmm.counter_parts import counter_parts
from linmstmm.wittrick_williams import ModeCounter, _beam_maps, _reduced_terms

MODELS = {path.stem: (lambda path=path: load_model(path)) for path in BUNDLED_MODELS}
MODELS |= {f"{kind} {seed}": (lambda kind=kind, seed=seed: random_model(kind, seed))
           for kind in KINDS for seed in range(3)}
MODELS |= {f"varied {seed}": (lambda seed=seed: varied_model(seed)[0]) for seed in range(15)}


def sparse_pencil(model, elements_per_beam):
    """(K, M, scale) of the coarse pencil from the assembly formed by scipy.sparse alone."""
    fe = assembled(model, elements_per_beam)
    K, M = fe.K.toarray(), fe.M.toarray()
    size = np.where(np.diag(M) > 0, np.diag(M), np.abs(np.diag(K)))
    scale = 1 / np.sqrt(np.where(size > 0, size, 1.0))
    return K * np.outer(scale, scale), M * np.outer(scale, scale), scale


def test_the_models_are_many_and_include_the_launchers():
    assert len(MODELS) >= 30 and {"mlrs", "launcher2"} <= set(MODELS)


@pytest.mark.parametrize("name", MODELS)
def test_pencil_is_the_sparse_assemblys(name, monkeypatch):
    model = MODELS[name]()
    coarse_pencil.cache_clear()
    pencils = {n: coarse_pencil(model, n) for n in (1, 2, 3)}
    monkeypatch.setattr(products, "DENSE_ENTRIES", 0)          # every product by scipy.sparse
    for n, pencil in pencils.items():
        K, M, scale = sparse_pencil(model, n)
        assert np.array_equal(pencil.K, K) and np.array_equal(pencil.M, M) and np.array_equal(pencil.scale, scale)
        assert pencil.rigid_body_modes == assemble(model, n).rigid_modes.shape[1]
    coarse_pencil.cache_clear()


@pytest.mark.parametrize("name", MODELS)
def test_compiled_products_are_the_numpy_route_s(name):
    model = MODELS[name]()
    for n in (1, 2, 3):
        compiled, reference = assembled(model, n, forms=pencil_forms), assembled(model, n)
        formed = small(compiled.parts.T.shape[1], compiled.parts.n_full)     # by the kernels, else by scipy
        assert (compiled.G is None) == formed and (formed or n > 1)
        K, M = (matrix if isinstance(matrix, np.ndarray) else matrix.toarray() for matrix in (reference.K, reference.M))
        assert np.array_equal(scipy_csr(compiled.K).toarray(), K) and np.array_equal(scipy_csr(compiled.M).toarray(), M)
        assert np.array_equal(compiled.D, reference.D)
    parts = counter_parts(model)
    for ours, theirs in zip(_reduced_terms(parts, "compiled") + _beam_maps(parts, "compiled"),
                            _reduced_terms(parts, "numpy") + _beam_maps(parts, "numpy")):
        assert ours.shape == theirs.shape and np.array_equal(ours, theirs)


@pytest.mark.parametrize("name", MODELS)
def test_compiled_scaling_is_the_numpy_route_s(name):
    """The coarse pencil scaled to unit mass per unknown by the compiled kernel, against
    numpy's scaling, bit for bit: on each model's assembled pencil at one and two
    elements per beam, and with some unknowns' mass (and stiffness) made zero."""
    model = MODELS[name]()
    for n in (1, 2):
        fe = assembled(model, n)
        K, M = (matrix if isinstance(matrix, np.ndarray) else matrix.toarray() for matrix in (fe.K, fe.M))
        bare, loose = np.arange(K.shape[0]) % 3 == 0, np.arange(K.shape[0]) % 6 == 0
        light, stiff = M.copy(), K.copy()
        light[bare], light[:, bare] = 0.0, 0.0
        stiff[loose], stiff[:, loose] = 0.0, 0.0
        for pencil in ((K, M), (K, light), (stiff, light)):
            for ours, theirs in zip(unit_scaled(*pencil), _unit_scaled(*pencil)):
                assert np.array_equal(ours, theirs)


def test_three_elements_at_a_node_leave_the_mass_to_the_numpy_route():
    """Where three beams meet, a position of the full mass is given three times: its
    sum is scipy's to order, and the compiled forms leave the assembly to the numpy
    route (the same K and M as the reference)."""
    points = {"hub": np.zeros(3), "x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.2, 0.0]),
              "z": np.array([0.1, 0.2, 0.9])}
    beams = tuple(make_beam(f"arm {end}", "hub", end, points) for end in ("x", "y", "z"))
    model = Model("star", points, rigids=(make_rigid("tip", ["x"], 2.0, [1.0, 0.0, 0.1], [0.1, 0.2, 0.3]),),
                  beams=beams, boundary={"y": fixed()})
    for n in (1, 2):
        compiled, reference = assembled(model, n, forms=pencil_forms), assembled(model, n)
        assert compiled.G is not None                                   # the numpy route formed them
        assert np.array_equal(compiled.K, reference.K) and np.array_equal(compiled.M, reference.M)


def test_inertia_screen_passes_over_only_bodies_left_unchanged():
    rng = np.random.default_rng(7)
    least_mass, least_inertia = 1.0, 1e-3
    bodies, passed_over_near = [], 0
    for _ in range(400):
        principal = np.array([rng.uniform(0.5, 1.0), rng.uniform(0.5, 1.0),
                              least_inertia * 10.0 ** rng.uniform(-1.0, 1.0)])   # the least near the threshold
        turn = random_rotation(rng)
        tensor = (turn * principal) @ turn.T
        bodies.append(make_rigid("b", ("p",), 10.0, (0.0, 0.0, 0.0), (tensor + tensor.T) / 2))
    masses = np.array([body.mass for body in bodies])
    tensors = np.array([body.inertia for body in bodies])
    looked_at = _maybe_negligible(masses, tensors, least_mass, least_inertia)
    for body, look in zip(bodies, looked_at):
        if not look:
            assert _body_mass_kept(body, least_mass, least_inertia) is body
            passed_over_near += np.linalg.eigvalsh(body.inertia)[0] < 10 * least_inertia
    assert passed_over_near > 0 and looked_at.any()         # the screen acted, and left some to the full check


def test_negligible_masses_keep_the_model_s_own_node_constraints():
    """A body of 1e-16 of the others' mass is rounding, removed before assembly: the
    assembly asks for the node constraints of the model itself (so the coarse pencil
    shares the counter's) and gives them the masses left, the same arrays as
    assembling the model with that body's mass removed from the start."""
    model = random_model("tree", 1)
    heavy = model.rigids[0]
    tiny = replace(heavy, mass=1e-16 * heavy.mass, inertia=1e-16 * heavy.inertia)
    model = replace(model, rigids=(tiny,) + model.rigids[1:])
    light = _negligible_mass_removed(model)
    assert light is not model and light.rigids[0].mass == 0.0
    for n in (1, 2, 3):
        given, made = assembled(model, n), assembled(light, n)
        assert given.model is not model
        for a, b in zip((given.parts.T, given.M, given.K, given.G), (made.parts.T, made.M, made.K, made.G)):
            a, b = (m if isinstance(m, np.ndarray) else as_scipy(m).toarray() for m in (a, b))
            assert np.array_equal(a, b)
        assert np.array_equal(given.D, made.D)
    kept_node_constraints.cache_clear()
    ModeCounter(model, "numpy")
    coarse_pencil.cache_clear()
    coarse_pencil(model, 2)
    assert kept_node_constraints.cache_info().misses == 1     # made for the counter, kept for the pencil
    coarse_pencil.cache_clear()
