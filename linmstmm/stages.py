"""The stages of long computations, told to whoever listens.

The solvers call :func:`report` as each stage starts ("deducing Ū_all",
"finding roots", ...); nothing happens unless a listener is installed by
:func:`listening` (the command line's progress bars on stderr). The listener
is a context variable, so it is local to the thread or task that installed it.
"""
from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar

_LISTENER: ContextVar[Callable[[str], None] | None] = ContextVar("stage listener", default=None)


def report(stage: str) -> None:
    """Tell the listener, if one is installed, that ``stage`` starts.

    Parameters
    ----------
    stage : str
        A short phrase, e.g. "finding roots".
    """
    listener = _LISTENER.get()
    if listener is not None:
        listener(stage)


@contextmanager
def listening(listener: Callable[[str], None]) -> Iterator[None]:
    """Call ``listener(stage)`` for every stage reported inside the ``with`` block.

    Parameters
    ----------
    listener : callable
        Called with each stage's phrase.

    Yields
    ------
    None
    """
    token = _LISTENER.set(listener)
    try:
        yield
    finally:
        _LISTENER.reset(token)
