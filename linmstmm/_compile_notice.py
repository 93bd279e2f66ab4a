"""One line on stderr when numba compiles a kernel of this package, once per process.

The kernels are compiled on their first use on a machine (``@njit(cache=True)``)
and loaded from numba's cache after: up to about a minute of CPU once per
install, 0.3-0.7 s to load in each new process. A first run would otherwise sit
silent for that long. numba announces a compilation (its
``numba:compile`` event) only where its cache has no kernel for the call, so
a run that loads every kernel from the cache prints nothing.

Every kernel module imports :func:`announce_compiles` and calls it before its
first kernel: the listener is installed once, whichever module loads first.
"""
from __future__ import annotations

import sys

from numba.core import event

#: What a first run on a machine prints, once, before its first compilation.
NOTICE = ("linmstmm: compiling the numba kernels for this machine (once per install, "
          "up to about a minute; later runs load them from numba's cache)")

_installed = False


class _FirstCompilation(event.Listener):
    """Prints NOTICE to stderr at the first compilation of a linmstmm kernel in this process."""

    def __init__(self):
        self.told = False

    def on_start(self, compilation) -> None:
        if self.told or not _ours(compilation.data):
            return
        self.told = True
        print(NOTICE, file=sys.stderr, flush=True)

    def on_end(self, compilation) -> None:
        """Nothing at the end: the notice is said before the wait."""


def _ours(details) -> bool:
    """Whether a ``numba:compile`` event's details name a function of this package."""
    function = getattr(details.get("dispatcher") if isinstance(details, dict) else None, "py_func", None)
    return getattr(function, "__module__", "").startswith("linmstmm")


def announce_compiles() -> None:
    """Install the listener that prints NOTICE (once per process; later calls do nothing)."""
    global _installed
    if not _installed:
        event.register("numba:compile", _FirstCompilation())
        _installed = True
