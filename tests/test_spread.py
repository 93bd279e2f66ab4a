"""Batches shared among threads (linmstmm.spread): every item evaluated once, the
same numbers as on one thread, and a piece's error raised in the caller."""
from __future__ import annotations

import multiprocessing
import threading
import time

import numpy as np
import pytest

from linmstmm import spread
from linmstmm.compiled_model import compiled_system
from linmstmm.model import load_model


@pytest.mark.parametrize("cores", [1, 2, 4])
@pytest.mark.parametrize("size", [0, 1, 7, 8, 9, 100, 513])
def test_every_item_once(monkeypatch, cores, size):
    monkeypatch.setattr(spread, "cores", lambda: cores)
    seen = np.zeros(size, dtype=int)

    def task(start, stop):
        seen[start:stop] += 1

    spread.spread(task, size)
    assert np.all(seen == 1)


@pytest.mark.parametrize("size, min_batch, threaded", [(20, 24, False), (24, 24, True), (7, 8, False), (8, 8, True)])
def test_a_batch_below_its_minimum_stays_on_the_calling_thread(monkeypatch, size, min_batch, threaded):
    """Cheap items (the Wittrick–Williams counts) are shared only from a larger batch:
    below ``min_batch`` every piece runs on the calling thread."""
    monkeypatch.setattr(spread, "cores", lambda: 2)
    callers = set()

    def task(start, stop):
        callers.add(threading.get_ident())
        time.sleep(0.01)  # long enough for the other thread to claim a piece

    spread.spread(task, size, min_batch)
    assert (callers != {threading.get_ident()}) == threaded


def test_a_piece_that_fails_raises_in_the_caller(monkeypatch):
    monkeypatch.setattr(spread, "cores", lambda: 2)

    def task(start, stop):
        if start <= 50 < stop:
            raise ValueError("piece failed")

    with pytest.raises(ValueError, match="piece failed"):
        spread.spread(task, 100)


@pytest.mark.parametrize("cores", [1, 2, 3])
def test_a_shared_batch_gives_the_bits_of_single_evaluations(monkeypatch, cores):
    """det Ū_all of the launcher over 64 frequencies, real and complex: bit for bit
    what one frequency at a time gives, however the batch is shared."""
    monkeypatch.setattr(spread, "cores", lambda: cores)
    determinant = compiled_system(load_model("models/mlrs/mlrs.toml"), engine="compiled").determinant
    for omegas in (np.geomspace(1.0, 2e4, 64), np.geomspace(1.0, 2e4, 64) * np.exp(0.01j)):
        sign, log_abs = determinant.log_det(omegas)
        alone = [determinant.log_det(omega) for omega in omegas]
        assert np.array_equal(sign, np.concatenate([s for s, _ in alone]))
        assert np.array_equal(log_abs, np.concatenate([v for _, v in alone]))


def _spread_sum(size: int) -> int:
    """The sum of range(size), its pieces added on the threads of :func:`spread.spread`."""
    total, lock = [0], threading.Lock()

    def task(start, stop):
        with lock:
            total[0] += sum(range(start, stop))

    spread.spread(task, size)
    return total[0]


def test_a_forked_child_shares_its_batches_on_threads_of_its_own(monkeypatch):
    """A process forked after the pool started (a sweep's worker processes) gets a pool of
    its own: the parent's threads are not in the child (it waited for ever)."""
    monkeypatch.setattr(spread, "cores", lambda: 2)
    assert _spread_sum(1000) == sum(range(1000))  # the pool exists in the parent now
    context = multiprocessing.get_context("fork")
    with context.Pool(1) as pool:
        assert pool.apply_async(_spread_sum, (1000,)).get(timeout=60) == sum(range(1000))


def test_the_caller_waits_for_no_thread_that_has_not_started(monkeypatch):
    """On a machine whose other cores are busy a helper thread may not run for a long
    while: the caller does every piece itself and returns, without waiting for it
    (it used to wait for each helper to start and find nothing left)."""
    monkeypatch.setattr(spread, "cores", lambda: 2)
    assert _spread_sum(100) == sum(range(100))  # the pool exists now
    release = threading.Event()
    for _ in range(spread._pool_threads):  # every thread of the pool busy elsewhere
        spread._pool.submit(release.wait, 60)
    try:
        seen, finished = np.zeros(100, dtype=int), threading.Event()

        def task(start, stop):
            seen[start:stop] += 1

        caller = threading.Thread(target=lambda: (spread.spread(task, 100), finished.set()))
        caller.start()
        assert finished.wait(20)
        assert np.all(seen == 1)
    finally:
        release.set()


@pytest.mark.parametrize("cores", [1, 2])
def test_a_failed_piece_stops_the_pieces_not_begun(monkeypatch, cores):
    """After a piece fails, the pieces no thread has begun are dropped (an interrupted
    batch of 512 frequencies does not run to its end first), and the error is raised."""
    monkeypatch.setattr(spread, "cores", lambda: cores)
    ran = []

    def task(start, stop):
        ran.append(start)
        raise KeyError("first piece")

    with pytest.raises(KeyError):
        spread.spread(task, 1000)
    assert len(ran) <= cores
