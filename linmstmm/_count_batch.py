"""The compiled Wittrick–Williams count at many frequencies in one call.

:func:`counts` runs :func:`linmstmm._stiffness_kernels.ordered_count` at each
frequency of an array, and the dense :func:`~linmstmm._stiffness_kernels.count`
where that one refuses, as :class:`linmstmm.wittrick_williams.ModeCounter` did
one Python call at a time: the same answers, without the dispatch of fifteen
arguments per frequency (2.5 of the 10 µs a count took on the launcher).

Numba keeps cached machine code by the source of the function that defines it
and the values it closes over, not by the kernels it calls from another file
(its documented limit, see :mod:`linmstmm._kernels`): :func:`counts` closes
over a digest of the source files its kernels are compiled from, so that an edit
to any of them compiles it anew instead of running the old code from the cache.
"""
from __future__ import annotations

import hashlib
from pathlib import Path

from numba import njit

from linmstmm import _lapack, _stiffness_kernels, dynamic_stiffness
from linmstmm._stiffness_kernels import REFUSED, count, ordered_count


def source_digest(*modules) -> int:
    """A 56-bit digest of the source files of ``modules`` (module objects)."""
    digest = hashlib.sha256()
    for module in modules:
        digest.update(Path(module.__file__).read_bytes())
    return int.from_bytes(digest.digest()[:7], "little")


def _batched(digest: int):
    """:func:`counts`, closing over ``digest`` (see the module's note on caching)."""

    @njit(cache=True, nogil=True)
    def counts(omegas, beams, maps, columns, static, mass, singular_pivot, most_growth, plan, terms, buffers,
               matrix, magnitude, work, out):
        """J(ω) at each of ``omegas`` (m,) rad/s into ``out`` (m,) int64, −1 where undecided:
        :func:`~linmstmm._stiffness_kernels.ordered_count` with ``plan``, ``terms`` and
        ``buffers``, else :func:`~linmstmm._stiffness_kernels.count` with ``columns``,
        ``static``, ``mass`` and the scratch ``matrix``, ``magnitude``, ``work``."""
        for i in range(omegas.size):
            found = ordered_count(omegas[i], beams, maps, singular_pivot, most_growth, plan, terms, buffers)
            if found == REFUSED:
                found = count(omegas[i], beams, maps, columns, static, mass, singular_pivot, matrix, magnitude,
                              work)
            out[i] = found + 0 * digest  # (the digest is part of the cache's key, not of the answer)

    return counts


counts = _batched(source_digest(_stiffness_kernels, dynamic_stiffness, _lapack))
