"""The compiled walk of the carry (linmstmm._walk_kernels, used by
linmstmm.program.compile_program) writes, integer for integer and bit for bit, the
program, constants' places and beams the Python walk (linmstmm.program._walked, the
readable reference) writes: on the bundled models, models with joints and with
released unknowns, and 200 random models."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from linmstmm import compiled_walk, godunov, program
from linmstmm.deduction import Deduction
from linmstmm.model import load_model
from linmstmm.nullspace import release_indeterminate
from linmstmm.topology import build_topology
from random_models import KINDS, random_model
from test_indeterminate_probes import RELEASING
from test_joints import beam_on_joint, four_bar, pinned_bars, sliding_carts
from test_program_layout import BUNDLED, RELEASED

MODELS = Path(__file__).resolve().parents[1] / "models"
RANDOM_SEEDS = 40  # of each kind: 200 random models


def _models():
    yield from (load_model(MODELS / f) for f in BUNDLED)
    yield from (four_bar(), pinned_bars(), sliding_carts(), beam_on_joint(["rx", "ry"]), beam_on_joint(["x", "rz"]))
    yield from (RELEASING[name]() for name in RELEASED)  # unknowns released


def _deduced(model) -> Deduction:
    deduction = Deduction(build_topology(model))
    release_indeterminate(deduction)
    return deduction


def _differences(compiled, reference) -> list[str]:
    """Names of the fields, constants or beams in which two walks' layouts differ (dtype,
    shape or bits)."""
    differences = []
    for field in dataclasses.fields(reference.program):
        a, b = (np.asarray(getattr(layout.program, field.name)) for layout in (compiled, reference))
        if a.dtype != b.dtype or a.shape != b.shape or a.tobytes() != b.tobytes():
            differences.append(field.name)
    for kind in ("rigid", "spring", "junction", "other_input", "joint"):
        if getattr(compiled.constants, kind) != getattr(reference.constants, kind):
            differences.append(f"constants.{kind}")
    if compiled.beams != reference.beams:
        differences.append("beams")
    return differences


@pytest.mark.parametrize("model", list(_models()), ids=lambda m: m.name)
def test_the_compiled_walk_writes_the_python_walks_program(model):
    deduction = _deduced(model)
    assert _differences(program._planned(deduction), program._planned_in_python(deduction)) == []


@pytest.mark.parametrize("kind", KINDS)
def test_the_compiled_walk_writes_the_python_walks_program_on_random_models(kind):
    differ = []
    for seed in range(RANDOM_SEEDS):
        deduction = _deduced(random_model(kind, seed))
        if differences := _differences(program._planned(deduction), program._planned_in_python(deduction)):
            differ.append((seed, differences))
    assert differ == []


def test_a_walk_that_outgrows_its_room_walks_again_with_more():
    deduction = _deduced(load_model(MODELS / "launcher2/launcher2.toml"))
    arrays, _ = compiled_walk._walk_input(deduction)
    roomy = compiled_walk._walked(arrays, godunov.FINAL_CARRIES, 1000 * arrays[3].shape[0])
    cramped = compiled_walk._walked(arrays, godunov.FINAL_CARRIES, 1)  # grown four times over and over
    assert len(roomy) == len(cramped)
    for a, b in zip(roomy, cramped):
        assert np.asarray(a).tobytes() == np.asarray(b).tobytes()
