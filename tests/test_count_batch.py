"""The compiled count at many frequencies in one call (linmstmm._count_batch) against
the count one frequency at a time: the sparse kernel, and the dense one where that
refuses, called from Python per frequency, on the bundled launchers and random
models, over frequencies that include refusals and undecided counts."""
from __future__ import annotations

import numpy as np
import pytest

from linmstmm import _count_batch, _lapack, dynamic_stiffness
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


def test_the_cached_batch_is_keyed_by_the_kernels_sources(tmp_path):
    """numba keys cached machine code by the function's own source and what it closes
    over: the batch closes over a digest of every source file its kernels come from,
    which an edit to one of them changes."""
    closed_over = [cell.cell_contents for cell in _count_batch.counts.py_func.__closure__]
    assert _count_batch.source_digest(kernels, dynamic_stiffness, _lapack) in closed_over
    first, second = tmp_path / "a.py", tmp_path / "b.py"
    first.write_text("x = 1\n")
    second.write_text("x = 2\n")

    class Module:
        def __init__(self, path):
            self.__file__ = str(path)

    assert _count_batch.source_digest(Module(first)) != _count_batch.source_digest(Module(second))
