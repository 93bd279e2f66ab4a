"""The walk of the carry (linmstmm.program) writes, for every model here, the program it
wrote before it was made cheaper: every array but the constants' matrices (those are
pinned element by element in test_program_constants.py), compared through a digest of
its exact bytes. The digests in data/program_layouts.json were made by that earlier walk
with :func:`layout_digest` below; a change that means to lay programs out otherwise
writes them anew."""
from __future__ import annotations

import dataclasses
import hashlib
import json
from pathlib import Path

import numpy as np
import pytest

from linmstmm import program
from linmstmm.compiled_model import forget_compiled_models
from linmstmm.deduction import Deduction
from linmstmm.model import load_model
from linmstmm.nullspace import release_indeterminate
from linmstmm.topology import build_topology
from random_models import KINDS, random_model
from test_indeterminate_probes import RELEASING
from test_joints import beam_on_joint, four_bar, pinned_bars, sliding_carts

MODELS = Path(__file__).resolve().parents[1] / "models"
DIGESTS = Path(__file__).resolve().parent / "data" / "program_layouts.json"
BUNDLED = ("mlrs/mlrs.toml", "launcher2/launcher2.toml", "cantilever_tip_mass.toml", "spring_mass_chain.toml",
           "dashpot_chain.toml")


def models():
    """The models whose layouts are pinned, by name."""
    yield from ((f, load_model(MODELS / f)) for f in BUNDLED)
    yield from ((f"{kind} {seed}", random_model(kind, seed)) for kind in KINDS for seed in range(6))
    yield from ((m.name, m) for m in (four_bar(), pinned_bars(), sliding_carts()))
    yield from ((f"beam on a joint {'+'.join(free)}", beam_on_joint(free)) for free in (["rx", "ry"], ["x", "rz"]))
    yield from ((name, RELEASING[name]()) for name in RELEASED)  # unknowns released


#: Models with statically indeterminate unknowns, released before the walk.
RELEASED = ("varied 24", "varied 358 (two)", "random loops 25", "random tree 19 with joints")


#: Fields left out of the digest: the constants' matrices, where each entry of Ū_all comes
#: from and where it goes for the determinant (found from the walk's arrays by
#: linmstmm._assembly_kernels, not by the walk).
NOT_DIGESTED = ("matrices", "assembly_sources", "assembly_targets", "block_sources", "block_targets",
                "block_offsets", "block_orders", "block_sign")


def layout_digest(model) -> str:
    """SHA-256 of every array of ``model``'s program (indeterminate unknowns released) but
    :data:`NOT_DIGESTED`: each field's name, shape and bytes (integers as int64, numbers as
    float64)."""
    forget_compiled_models()
    deduction = Deduction(build_topology(model))
    release_indeterminate(deduction)
    compiled = program.compile_program(deduction)
    digest = hashlib.sha256()
    for field in dataclasses.fields(compiled):
        if field.name in NOT_DIGESTED:
            continue
        value = np.asarray(getattr(compiled, field.name))
        value = value.astype(np.float64 if value.dtype.kind == "f" else np.int64)
        digest.update(f"{field.name} {value.shape}".encode())
        digest.update(value.tobytes())
    return digest.hexdigest()


@pytest.mark.parametrize("name, model", list(models()), ids=lambda x: x if isinstance(x, str) else "")
def test_the_walk_lays_every_program_out_as_before(name, model):
    assert layout_digest(model) == json.loads(DIGESTS.read_text())[name]
