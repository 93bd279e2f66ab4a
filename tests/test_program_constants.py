"""The constants of a compiled program are built for all elements of a kind at once
(linmstmm.program_constants): each must be, bit for bit, the matrix the numpy carry
(linmstmm.deduction.Deduction) builds for that element alone."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from linmstmm import program
from linmstmm.deduction import Deduction
from linmstmm.elements.rigid import force_extraction, position_incidence, rigid_transfer_parts
from linmstmm.elements.spring import joint_force, spring_constant_transfer
from linmstmm.model import load_model
from linmstmm.nullspace import release_indeterminate
from linmstmm.topology import build_topology
from random_models import KINDS, random_model
from test_joints import beam_on_joint, four_bar, pinned_bars, sliding_carts
from test_indeterminate_probes import RELEASING
from test_program_layout import RELEASED

MODELS = Path(__file__).resolve().parents[1] / "models"


def _models():
    yield from (load_model(MODELS / f) for f in ("mlrs/mlrs.toml", "launcher2/launcher2.toml"))
    yield from (random_model(kind, seed) for kind in KINDS for seed in range(4))
    yield from (four_bar(), pinned_bars(), sliding_carts(), beam_on_joint(["rx", "ry"]))
    yield from (RELEASING[name]() for name in RELEASED)  # unknowns released


def _bits(matrix) -> bytes:
    """The float64 bits of ``matrix`` padded to 12 × 12 (so −0.0 and 0.0 differ)."""
    out = np.zeros((12, 12))
    out[:matrix.shape[0], :matrix.shape[1]] = matrix
    return out.tobytes()


def _layout(model):
    """(deduction, walk) of ``model``, indeterminate unknowns released."""
    deduction = Deduction(build_topology(model))
    release_indeterminate(deduction)
    return deduction, program._planned(deduction)


def test_the_models_hold_every_kind_of_constant_and_released_unknowns():
    layouts = [_layout(model) for model in _models()]
    for kind in ("rigid", "spring", "junction", "other_input", "joint"):
        assert any(getattr(layout.constants, kind) for _, layout in layouts), kind
    assert any(deduction.released_columns.size for deduction, _ in layouts)


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_every_constant_is_the_numpy_carrys_matrix_bit_for_bit(model):
    deduction, layout = _layout(model)
    matrices, constants = layout.program.matrices, layout.constants
    expected = {}
    for e, kinematic, inertial in constants.rigid:
        expected[kinematic], expected[inertial] = deduction._polynomial_parts(e)
    for e, kinematic in constants.spring + [(None, index) for index in constants.junction]:
        expected[kinematic] = deduction._polynomial_parts(e)[0] if e is not None else np.eye(12)
    for e, k, forces, incidence in constants.other_input:
        _, expected[forces], expected[incidence] = deduction._other_inputs(e)[k]
    for e, force, jump in constants.joint:
        record = deduction.topology.elements[e].record
        expected[force] = joint_force(record.axes, record.released)
        expected[jump] = deduction.jump_state(e, 1).matrix[0]
    for index, matrix in expected.items():
        assert matrices[index].tobytes() == _bits(matrix), index
    revalued = program._revalued(layout, deduction)  # a refill writes the same bits
    assert revalued.matrices.tobytes() == matrices.tobytes()


def test_a_stack_of_elements_is_each_element_alone_bit_for_bit():
    rng = np.random.default_rng(5)
    n = 40
    mass = rng.uniform(0.1, 100.0, n)
    com, inp, out = rng.normal(size=(3, n, 3))
    roots = rng.normal(size=(n, 3, 3))
    inertia = roots @ np.swapaxes(roots, 1, 2)
    axes = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    k = rng.uniform(1e2, 1e8, (n, 6))
    k[rng.uniform(size=(n, 6)) < 0.25] = np.inf
    released = rng.uniform(size=(n, 6)) < 0.2
    k[released] = 0.0
    stacks = [rigid_transfer_parts(mass, com, inertia, inp, out), (force_extraction(inp, out),),
              (position_incidence(inp, out),), (spring_constant_transfer(k, axes, released),)]
    for i in range(n):
        alone = [rigid_transfer_parts(mass[i], com[i], inertia[i], inp[i], out[i]), (force_extraction(inp[i], out[i]),),
                 (position_incidence(inp[i], out[i]),), (spring_constant_transfer(k[i], axes[i], released[i]),)]
        for stacked, single in zip(stacks, alone):
            for a, b in zip(stacked, single):
                assert a[i].tobytes() == b.tobytes()
