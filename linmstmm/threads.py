"""One BLAS thread for the small dense algebra of this package.

Every matrix here is small (Ū_all of order tens, coarse finite-element
models of a few hundred unknowns): a multithreaded BLAS spends more on waking
its threads than on the arithmetic, and on a busy two-core machine far more —
the launcher's ten frequencies took 186 ms with the default threads and 26 ms
with one, the 84 × 84 predicting eigenproblem alone 48 ms against under 1 ms.
"""
from __future__ import annotations

import contextlib
import functools

_controller = None


def one_blas_thread():
    """Context manager: BLAS and LAPACK calls inside run on one thread."""
    global _controller
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - a dependency; without it, run as the machine is set
        return contextlib.nullcontext()
    if _controller is None:
        _controller = ThreadpoolController()
    return _controller.limit(limits=1, user_api="blas")


def single_blas_thread(function):
    """Decorator: run ``function`` inside :func:`one_blas_thread`."""
    @functools.wraps(function)
    def wrapped(*args, **kwargs):
        with one_blas_thread():
            return function(*args, **kwargs)
    return wrapped
