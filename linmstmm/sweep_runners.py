"""Where the steps of a parameter study run: here in order, in local processes, or on a
dask.distributed cluster (:func:`run_steps`); the results are the same bits either way.

A step that starts from another (a warm start) is submitted once that one is solved
(here and in processes), or handed its future (dask, whose scheduler orders them).
"""
from __future__ import annotations

import logging
import sys
from collections import defaultdict
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait

#: Seconds to wait for a dask scheduler given by address before giving up.
SCHEDULER_TIMEOUT = 10


def run_steps(models, solve, starts, workers: int, dask, progress: bool):
    """Every step solved: ([solution] in step order, a label saying what ran them).

    Parameters
    ----------
    models : list of Model
        One edited model per step.
    solve : callable
        ``solve(model, start=...)`` solves one step (picklable: it runs in other
        processes); ``start`` is the solution of the step it starts from, or None.
    starts : list of int or None
        Per step, the index of the step whose solution it starts from (None: a
        cold start); a step comes after the one it starts from.
    workers : int
        Local processes (1: here, in order).
    dask : None, "local", an address or a ``distributed.Client``
        Run on a dask.distributed cluster instead (:func:`linmstmm.sweep.sweep`).
    progress : bool
        A progress bar on stderr (only where stderr is a terminal).

    Returns
    -------
    tuple
        (list of solutions, str).
    """
    bar = _progress(len(models), progress)
    try:
        if dask is not None:
            return _on_dask(models, solve, starts, dask, workers, bar)
        if workers > 1:
            with ProcessPoolExecutor(max_workers=workers) as pool:
                return _dependent(pool.submit, models, solve, starts, bar), f"{workers} processes"
        return _dependent(_solved_now, models, solve, starts, bar), "serial"
    finally:
        bar.close()


def _dependent(submit, models, solve, starts, bar) -> list:
    """[StepSolution] in step order; ``submit(solve, model, start=...)`` gives a future, and a
    step is submitted once the step it starts from is solved."""
    after = defaultdict(list)
    for step, start in enumerate(starts):
        after[start].append(step)
    solutions = [None] * len(models)
    running = {submit(solve, models[step], start=None): step for step in after.pop(None)}
    while running:
        done, _ = wait(running, return_when=FIRST_COMPLETED)
        for future in done:
            step = running.pop(future)
            solutions[step] = future.result()
            bar.update()
            running.update({submit(solve, models[next_step], start=solutions[step]): next_step
                            for next_step in after.pop(step, ())})
    return solutions


def _solved_now(function, *args, **kwargs) -> Future:
    """A finished future of ``function(*args, **kwargs)``, run here (the serial runner)."""
    future = Future()
    future.set_result(function(*args, **kwargs))
    return future


def _on_dask(models, solve, starts, dask, workers, bar):
    """Run the steps on a dask.distributed cluster (see :func:`sweep`)."""
    from distributed import Client, LocalCluster

    if isinstance(dask, Client):
        return _dask_map(dask, models, solve, starts, bar), f"dask {dask.scheduler.address}"
    if dask == "local":
        with LocalCluster(n_workers=max(workers, 2), threads_per_worker=1, dashboard_address=None,
                          silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
            return (_dask_map(client, models, solve, starts, bar),
                    f"dask LocalCluster ({max(workers, 2)} workers)")
    with Client(dask, timeout=SCHEDULER_TIMEOUT) as client:
        return _dask_map(client, models, solve, starts, bar), f"dask {dask}"


def _dask_map(client, models, solve, starts, bar) -> list:
    """[StepSolution] of every model in order, solved on the cluster of ``client``; a step
    that starts from another is handed that step's future (the cluster orders them)."""
    from distributed import as_completed

    futures = []
    for model, start in zip(models, starts):  # a step's start comes before it
        futures.append(client.submit(solve, model, start=None if start is None else futures[start], pure=False))
    index = {future.key: step for step, future in enumerate(futures)}
    solutions = [None] * len(futures)
    for future in as_completed(futures):
        solutions[index[future.key]] = future.result()
        bar.update()
    return solutions


def _progress(total: int, wanted: bool):
    """A tqdm bar on stderr, silent unless ``wanted`` and stderr is a terminal."""
    from tqdm import tqdm

    return tqdm(total=total, unit="step", file=sys.stderr,
                disable=not (wanted and sys.stderr.isatty()))
