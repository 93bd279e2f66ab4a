"""The compiled count at many frequencies in one call (linmstmm._stiffness_kernels.counts) against
the count one frequency at a time: the sparse kernel, and the dense one where that
refuses, called from Python per frequency, on the bundled launchers and random
models, over frequencies that include refusals and undecided counts."""
from __future__ import annotations

import numpy as np
import pytest

from linmstmm import _stiffness_kernels as kernels
from linmstmm.model import load_model
from linmstmm.wittrick_williams import MOST_GROWTH, SINGULAR_PIVOT, ModeCounter
from random_models import KINDS, random_model

LAUNCHERS = ("models/mlrs/mlrs.toml", "models/launcher2/launcher2.toml")


def one_at_a_time(counter: ModeCounter, omega: float) -> int:
    """J(ω) by the sparse kernel, or the dense one where it refuses; −1 undecided."""
    matrix, magnitude, work, buffers = counter._new_scratch()
    table = counter._beam_table()
    found = kernels.ordered_count(omega, table, counter._maps, SINGULAR_PIVOT, MOST_GROWTH, *counter._plan, buffers)
    if found == kernels.REFUSED:
        found = kernels.count(omega, table, counter._maps, counter._columns, counter._static, counter._mass,
                              SINGULAR_PIVOT, matrix, magnitude, work)
    return found


@pytest.mark.parametrize("source", [*LAUNCHERS, *((kind, 0) for kind in KINDS)])
def test_counts_in_one_call_are_the_counts_one_at_a_time(source):
    model = load_model(source) if isinstance(source, str) else random_model(*source)
    counter = ModeCounter(model, "compiled")
    omegas = np.geomspace(1.0, 3e3, 1500)
    single = [one_at_a_time(counter, omega) for omega in omegas]
    # (a batch below COUNT_BATCH runs in one call on this thread; a larger one is shared out)
    for batch in (omegas[:20], omegas):
        counter._answers = {}
        counter.prefetch(batch)
        expected = [None if count < 0 else count for count in single[:batch.size]]
        assert [counter(omega) for omega in batch] == expected
    if isinstance(source, str):  # the launchers: the dense count takes some, and some are answered so
        sparse = [kernels.ordered_count(omega, counter._beam_table(), counter._maps, SINGULAR_PIVOT, MOST_GROWTH,
                                        *counter._plan, counter._new_scratch()[3]) for omega in omegas]
        assert kernels.REFUSED in sparse

