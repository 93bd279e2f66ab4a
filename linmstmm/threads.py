"""One BLAS thread for the small dense algebra of this package.

Every matrix here is small (Ū_all of order tens, coarse finite-element
models of a few hundred unknowns): a multithreaded BLAS spends more on waking
its threads than on the arithmetic, and on a busy two-core machine far more —
the launcher's ten frequencies took 186 ms with the default threads and 26 ms
with one, the 84 × 84 predicting eigenproblem alone 48 ms against under 1 ms.

The libraries are looked up once (threadpoolctl's controllers of the BLAS
loaded then) and each call only reads and sets their thread counts: threadpoolctl's
own ``limit`` takes stock of every library anew each time, 20-30 µs of a
launcher solve of 1 ms.
"""
from __future__ import annotations

import contextlib
import functools

_libraries = None  # threadpoolctl's controllers of the BLAS libraries, on the first call


def _blas_libraries() -> list:
    """Controllers of the BLAS libraries loaded when first asked for (empty without threadpoolctl)."""
    global _libraries
    if _libraries is None:
        try:
            from threadpoolctl import ThreadpoolController
        except ImportError:  # pragma: no cover - a dependency; without it, run as the machine is set
            _libraries = []
        else:
            _libraries = ThreadpoolController().select(user_api="blas").lib_controllers
    return _libraries


@contextlib.contextmanager
def one_blas_thread():
    """Context manager: BLAS and LAPACK calls inside run on one thread; the thread
    counts found on entry are set again on exit (a library at one thread already is
    left alone)."""
    libraries = _blas_libraries()
    before = [library.num_threads for library in libraries]
    for library, threads in zip(libraries, before):
        if threads != 1:
            library.set_num_threads(1)
    try:
        yield
    finally:
        for library, threads in zip(libraries, before):
            if threads != 1:
                library.set_num_threads(threads)


def single_blas_thread(function):
    """Decorator: run ``function`` inside :func:`one_blas_thread`."""
    @functools.wraps(function)
    def wrapped(*args, **kwargs):
        with one_blas_thread():
            return function(*args, **kwargs)
    return wrapped
