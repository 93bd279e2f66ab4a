"""Independent evaluations spread over the machine's cores, on threads.

The compiled kernels that evaluate det Ū_all and the Wittrick–Williams count
release Python's lock while they run (numba's ``nogil``), so a batch of
frequencies can be shared among threads of this process, each evaluating
its frequencies exactly as one thread would: the same numbers, bit for bit,
in any split. The work is handed out in pieces that each thread claims in
turn, the calling thread among them, so that on a machine whose other cores
are busy the caller does nearly all of it itself instead of waiting for a
thread that is not running.
"""
from __future__ import annotations

import math
import os
import threading
from concurrent.futures import ThreadPoolExecutor

#: Items below which a batch stays on the calling thread: handing a piece to
#: another thread costs about one evaluation (measured on the launcher: 4
#: frequencies on two threads took 80 µs each, against 84 µs on one).
MIN_BATCH = 8
#: Pieces per thread a batch is cut into (the last piece claimed is the
#: longest anyone waits for another thread).
PIECES_PER_THREAD = 3

_pool: ThreadPoolExecutor | None = None
_pool_threads = 0  # the pool's threads


def _forget_pool() -> None:
    """Drop the pool in a forked child: its threads stayed in the parent, and a pool
    whose threads do not exist takes work it never does (a sweep's worker processes
    waited for ever)."""
    global _pool, _pool_threads
    _pool, _pool_threads = None, 0


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_pool)


def cores() -> int:
    """Cores this process may run on (its CPU affinity where the system tells it)."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1  # pragma: no cover - systems without affinity


def spread(task, size: int, min_batch: int = MIN_BATCH) -> None:
    """Call ``task(start, stop)`` over consecutive pieces covering range(size), on this
    thread and on up to ``cores() - 1`` others.

    Parameters
    ----------
    task : callable (int, int) -> None
        Evaluates items start..stop-1 and stores them where the caller reads
        them; pieces never overlap. It must release Python's lock for the
        threads to run side by side (a ``nogil`` kernel).
    size : int
        Number of items.
    min_batch : int
        Items below which the batch stays on the calling thread, and per two of
        which a thread joins in (MIN_BATCH suits items that cost about one
        evaluation of det Ū_all; cheaper items want more).

    Raises
    ------
    Exception
        Whatever a piece raised (the first one met).
    """
    threads = min(cores(), size // (min_batch // 2)) if size >= min_batch else 1
    if threads <= 1:
        task(0, size)
        return
    global _pool, _pool_threads
    if _pool_threads < threads - 1:  # none yet, or too few: a larger one replaces it
        if _pool is not None:
            _pool.shutdown(wait=False)
        _pool, _pool_threads = ThreadPoolExecutor(max_workers=threads - 1, thread_name_prefix="linmstmm"), threads - 1
    piece = max(1, math.ceil(size / (PIECES_PER_THREAD * threads)))
    pieces = math.ceil(size / piece)
    lock, all_done = threading.Lock(), threading.Event()
    claimed, done, errors = [0], [0], []

    def work() -> None:
        while True:
            with lock:
                start = claimed[0]
                claimed[0] = min(start + piece, size)
            if start >= size:
                return
            failed = None
            try:
                task(start, min(start + piece, size))
            except BaseException as error:  # raised in the caller; the pieces not begun are dropped
                failed = error
            with lock:
                done[0] += 1
                if failed is not None:
                    errors.append(failed)
                    done[0] += math.ceil((size - claimed[0]) / piece)
                    claimed[0] = size
                if done[0] == pieces:
                    all_done.set()

    for _ in range(threads - 1):
        _pool.submit(work)
    work()
    all_done.wait()  # for the pieces others are running; a thread that has not started finds none left
    if errors:
        raise errors[0]
