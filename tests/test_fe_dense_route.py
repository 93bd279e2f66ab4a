"""Small models' assembly in numpy against scipy.sparse, bit for bit.

Small models are assembled with numpy (:mod:`linmstmm.fe.products`): products
formed term by term in the order scipy.sparse sums them, sums of at most two
masses at a position, the constraint rows and the beams' maps taken out densely.
Each must give exactly what scipy.sparse gives, so the FE route's frequencies,
the Wittrick–Williams counts and the coarse predictions do not change:

* each product, congruence and row extraction equals scipy's on random sparse
  matrices (entries of many magnitudes, exact cancellations, unsorted rows);
* masses summed where no position has more than two entries equal scipy's sums;
* the assembled T, M, K, G and D of the launcher, the second launcher, random
  models and the mixed model of the assembly test are the same arrays whether
  formed densely or by scipy.sparse (the route forced each way);
* the counter's matrices equal scipy.sparse's forms of them;
* a model whose every segment is clamped has no rigid motion, as the full
  search for them finds, and the rigid-body modes counted without forming
  them are as many as :func:`~linmstmm.fe.assembly.assemble` forms.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp
from random_models import KINDS, random_model
from test_fe_assembly import mixed_model
from varied_models import varied_model

import linmstmm.fe.products as products
from linmstmm.fe.assembly import assemble, assembled, constrained_parts
from linmstmm.fe.layout import _layout
from linmstmm.fe.products import (
    congruence,
    dense_product,
    dense_rows,
    rows_scaled,
    transposed,
)
from linmstmm.fe.rigid_motions import _components, _edges, _held_everywhere, _rigid_motions, rigid_mode_count
from linmstmm.fe.sparse import as_scipy, compressed_of_summed, scipy_csr
from linmstmm.model import load_model
from linmstmm.wittrick_williams import ModeCounter

MODELS = {
    "launcher": lambda: load_model("models/mlrs/mlrs.toml"),
    "launcher 2": lambda: load_model("models/launcher2/launcher2.toml"),
    "tree": lambda: random_model("tree", 3),
    "loops": lambda: random_model("loops", 4),            # three masses meet at a point
    "floating loops": lambda: random_model("floating_loops", 5),
    "mixed": mixed_model,
    "mixed floating": lambda: mixed_model(held=False),
}


def random_sparse(rng, n, m, density) -> sp.csr_matrix:
    """(n, m) CSR with entries of random sign and magnitude (1e-6 to 1e6), some zeros."""
    def values(k):
        return rng.choice([0.0, 1.0, -1.0], k) * rng.standard_normal(k) * 10.0 ** rng.integers(-6, 7, k)
    return sp.random(n, m, density=density, format="csr", random_state=rng, data_rvs=values)


def same_csr(a, b) -> bool:
    """Whether two CSR matrices store the same entries in the same order."""
    return all(np.array_equal(x, y) for x, y in ((a.indptr, b.indptr), (a.indices, b.indices), (a.data, b.data)))


def test_products_are_summed_as_scipy_sums_them():
    rng = np.random.default_rng(1)
    for trial in range(200):
        n, m, p = rng.integers(1, 30, 3)
        a, b = random_sparse(rng, n, m, rng.uniform(0.05, 0.6)), random_sparse(rng, m, p, rng.uniform(0.05, 0.6))
        if trial % 4 == 0:                                 # an exact cancellation in every entry
            a, b = sp.hstack([a, a]).tocsr(), sp.vstack([b, -b]).tocsr()
            m = 2 * m
        assert np.array_equal(dense_product(a, b), (a @ b).toarray())
        unsorted = a @ random_sparse(rng, m, m, 0.3)       # a product's rows are not sorted
        assert np.array_equal(dense_product(unsorted, b), (unsorted @ b).toarray())
        c = random_sparse(rng, n, p, 0.3)
        k = rng.standard_normal(n)
        assert np.array_equal(dense_product(transposed(a), c), (a.T @ c).toarray())
        assert np.array_equal(dense_product(transposed(a), rows_scaled(a, k)), (a.T @ a.multiply(k[:, None])).toarray())
        weighted = sp.csc_matrix((a.data * np.repeat(k, np.diff(a.indptr)), a.indices, a.indptr), shape=(m, n))
        assert np.array_equal(dense_product(transposed(a, k), a), (weighted @ a).toarray())
        square = random_sparse(rng, n, n, 0.3)
        assert np.array_equal(congruence(a, square), (a.T @ square @ a).toarray())
        rows = rng.integers(0, n, (3, 4))
        assert np.array_equal(dense_rows(unsorted, rows), unsorted[rows.ravel()].toarray().reshape(3, 4, m))


def test_congruence_of_kept_dofs_is_scipys():
    """A congruence whose T keeps every DOF the matrix touches as it is (one 1.0 in a
    column of its own) moves the matrix's entries; T that joins two of them, scales
    one or slaves one to others, and a matrix with entries off those rows, take the
    general route. Each is scipy's product, entry for entry."""
    rng = np.random.default_rng(4)
    for trial in range(300):
        n, m = rng.integers(8, 40), rng.integers(4, 30)
        T = random_sparse(rng, n, m, 0.2).tolil()
        touched = rng.choice(n, rng.integers(1, min(n, m) + 1), replace=False)
        columns = rng.choice(m, touched.size, replace=False)
        for dof, column in zip(touched, columns):
            T[dof, :] = 0.0
            T[dof, column] = 1.0
        if trial % 4 == 1:                                  # two DOFs moved to one column
            T[touched[0], :] = T[touched[-1], :]
        if trial % 4 == 2:                                  # one scaled, or slaved to several
            T[touched[0], columns[0]] = rng.choice([2.0, -1.0])
            T[touched[0], (columns[0] + 1) % m] = rng.standard_normal()
        T = T.tocsr()
        T.eliminate_zeros()
        square = sp.lil_matrix((n, n))
        block = random_sparse(rng, touched.size, touched.size, 0.6).toarray()
        square[np.ix_(touched, touched)] = block + block.T
        if trial % 4 == 3:                                  # an entry on a DOF T does not keep
            square[touched[0], (touched[0] + 1) % n] = 1.0
        square = square.tocsr()
        assert np.array_equal(congruence(T, square), (T.T @ square @ T).toarray())


def test_products_would_differ_in_another_order():
    """The comparisons above can fail: a dense BLAS product rounds otherwise."""
    rng = np.random.default_rng(2)
    a, b = random_sparse(rng, 30, 30, 0.5), random_sparse(rng, 30, 30, 0.5)
    assert not np.array_equal(a.toarray() @ b.toarray(), (a @ b).toarray())


def test_masses_are_summed_as_scipy_sums_them():
    rng = np.random.default_rng(3)
    for size, entries, repeats in ((12, 60, 1), (12, 60, 2), (12, 60, 3), (200, 3000, 2)):
        rows, cols = rng.integers(0, size, entries), rng.integers(0, size, entries)
        rows, cols = np.tile(rows, repeats), np.tile(cols, repeats)   # three at a position, or
        values = rng.standard_normal(rows.size) * 10.0 ** rng.integers(-6, 7, rows.size)  # many: scipy's
        values[::7] = 0.0
        reference = sp.coo_matrix((values, (rows, cols)), shape=(size, size)).tocsr()
        reference.eliminate_zeros()
        assert same_csr(scipy_csr(compressed_of_summed(rows, cols, values, (size, size))), reference)


def assembled_arrays(model):
    """T, M, K, G (as stored) and D of ``model`` with two elements per beam."""
    assembly = assembled(model, 2)
    return [assembly.parts.T, scipy_csr(assembly.M), scipy_csr(assembly.K), assembly.G], assembly.D


@pytest.mark.parametrize("name", MODELS)
def test_dense_and_sparse_assembly_agree(name, monkeypatch):
    model = MODELS[name]()
    dense, d_dense = assembled_arrays(model)
    monkeypatch.setattr(products, "DENSE_ENTRIES", 0)          # every product by scipy.sparse
    sparse, d_sparse = assembled_arrays(model)
    assert all(same_csr(a, b) for a, b in zip(dense, sparse))
    assert np.array_equal(d_dense, d_sparse)


@pytest.mark.parametrize("name", MODELS)
def test_counter_matrices_are_scipys(name):
    model = MODELS[name]()
    counter = ModeCounter(model, "numpy")
    parts = constrained_parts(model, 1)
    T = as_scipy(parts.T)
    springs = scipy_csr(parts.spring_strains.compressed(parts.n_full)) @ T
    stiffness = np.concatenate(parts.spring_stiffness) if parts.spring_stiffness else np.zeros(0)
    assert np.array_equal(counter._static, (springs.T @ springs.multiply(stiffness[:, None])).toarray())
    mass = scipy_csr(parts.rigid_mass.compressed(parts.n_full, parts.n_full))
    assert np.array_equal(counter._mass, (T.T @ mass @ T).toarray())
    for dofs, to_local, maps, columns in zip(*(part[:, 0] for part in parts.beam_maps), counter._maps,
                                             counter._columns):
        rows = T[dofs].toarray()
        touched = np.flatnonzero(np.any(rows != 0.0, axis=0))
        assert np.array_equal(columns[:touched.size], touched) and np.all(columns[touched.size:] == T.shape[1])
        assert np.array_equal(maps[:, :touched.size], to_local @ rows[:, touched])
        assert not np.any(maps[:, touched.size:])


@pytest.mark.parametrize("name", MODELS)
def test_rigid_modes_counted_as_formed(name):
    model = MODELS[name]()
    fe = assemble(model, 2)
    parts = constrained_parts(model, 2)
    assert rigid_mode_count(model, parts.layout, parts.masters, fe.M.toarray()) == fe.rigid_modes.shape[1]
    layout = _layout(model, 2)
    if _held_everywhere(model, layout):                    # the shortcut: the full search finds none either
        assert _rigid_motions(model, layout)[0].shape[1] == 0


def mesh_segments_clamped(model, layout) -> bool:
    """Whether every segment of the mesh's own edge arrays (:func:`_components`, joints
    left out) holds a point fixed in all six components."""
    clamped = [layout.index.points[point] for point, fixed in model.boundary.items() if all(fixed)]
    edges, joints = _edges(model, layout)
    segments = _components(edges[~joints], layout.n_nodes)
    return bool(clamped) and bool(np.bincount(segments[clamped], minlength=segments.max() + 1).all())


def test_clamped_everywhere_is_what_the_meshs_segments_say():
    """The union–find on points and mass centres against the segments of the meshed
    edges, on random, varied and jointed models, each also with random boundaries."""
    rng = np.random.default_rng(3)
    models = [random_model(kind, seed) for kind in KINDS for seed in range(4)]
    models += [varied_model(seed)[0] for seed in range(8)] + [mixed_model(), mixed_model(held=False)]
    answers = set()
    for model in models:
        variants = [model]
        for _ in range(3):
            points = rng.choice(list(model.points), size=min(3, len(model.points)), replace=False)
            variants.append(replace(model, boundary={point: rng.random(6) < 0.9 for point in points}))
        for variant in variants:
            for n in (1, 2):
                layout = _layout(variant, n)
                held = _held_everywhere(variant, layout)
                assert held == mesh_segments_clamped(variant, layout)
                answers.add(held)
    assert answers == {True, False}


def test_clamped_everywhere_is_recognised():
    assert _held_everywhere(MODELS["launcher"](), _layout(MODELS["launcher"](), 2))
    assert not _held_everywhere(mixed_model(held=False), _layout(mixed_model(held=False), 2))
