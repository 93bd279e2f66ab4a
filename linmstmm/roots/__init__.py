"""Roots of det Ū_all(ω): count, scan, bracket, refine, multiplicity.

Nothing is missed because every root found is checked against a count by
the argument principle (:mod:`linmstmm.counting`).

The fast path (:meth:`RootFinder._scan_ahead`) scans (sign, log|det|)
upwards until it has seen enough candidates, polishes them all at once and
keeps the result only if one count from the floor agrees: the count of
det with the found roots divided out (:func:`~linmstmm.counting.deflated`)
must be zero, which a missed root or a false one would break. Where it is
not, the missing roots are looked for in the stored scan and by deflated
counts (:meth:`RootFinder._closed`); failing that, the search works
segment by segment upwards:

1. a count, then a scan on a geometric grid of at least ``points_per_root``
   points per counted root;
2. Newton starts where the line through |det| crosses zero in each sign
   change, and at local minima of log|det| without a sign change (even
   multiplicity, close pairs);
3. Newton on the local linearisation (:meth:`RootFinder.polish`, all starts
   at once) converges to machine precision on simple and semisimple multiple
   roots alike; the multiplicity comes from the linearised pencil's
   near-zero offsets, confirmed by a count over a small circle;
4. bisection on the count finds whatever the scan missed, or raises an
   honest error if float64 cannot separate the roots.

Everything works on (sign, log|det|), so nothing overflows; the evaluation
itself is the stable (orthonormalised) one of :mod:`linmstmm.deduction`.

Modules
-------
:class:`RootFinder` (:mod:`~linmstmm.roots.finder`) holds the search's state
and coordinates it; its searches, :meth:`~RootFinder.find` and
:meth:`~RootFinder.find_near`, return a frozen :class:`RootSearchResult`
(:mod:`~linmstmm.roots.result`): the roots with the search's diagnostics.
Each step is a function of its own module that takes the finder as its first
argument ``finder`` and is the finder's method of the same name (with a
leading underscore where it is internal), so the steps call each other
through the finder:

* :mod:`~linmstmm.roots.fast_path` — scan ahead, polish, close by one count;
* :mod:`~linmstmm.roots.brackets` — sign-change brackets and quiet minima;
* :mod:`~linmstmm.roots.segments` — the segment search and bisection on counts;
* :mod:`~linmstmm.roots.pencil` — Newton on the pencil (Ū, dŪ/dω);
* :mod:`~linmstmm.roots.clusters` — clusters of close roots, multiplicities;
* :mod:`~linmstmm.roots.certify` — argument-principle counts that certify;
* :mod:`~linmstmm.roots.floor` — nothing hides below the floor;
* :mod:`~linmstmm.roots.top_count` — the list at the end against the count at its top;
* :mod:`~linmstmm.roots.settings` — scan densities, limits, frequency ratios;
* :mod:`~linmstmm.roots.result` — the frozen result of a search.
"""

from __future__ import annotations

from linmstmm.roots.finder import RootFinder
from linmstmm.roots.result import RootSearchResult
from linmstmm.roots.segments import SearchAtDefaultRtol
from linmstmm.roots.settings import (
                                     CEILING_RATIO,
                                     CERTIFIED_STEP,
                                     CIRCLE_MAX_POINTS,
                                     CIRCLE_POINTS,
                                     DEFAULT_SCALE,
                                     DEFLATED_MAX_POINTS,
                                     DEFLATED_POINTS,
                                     FINE_SCAN_RATIO,
                                     FIRST_CHUNK_RATIO,
                                     FIRST_SEGMENT_RATIO,
                                     FLOOR_CHECK,
                                     FLOOR_MARGIN,
                                     FLOOR_RATIO,
                                     MAX_RTOL,
                                     MAX_XTOL,
                                     MIN_RTOL,
                                     MIN_POINTS_PER_OCTAVE,
                                     POINTS_PER_OCTAVE,
                                     PREDICTION_MARGIN,
                                     SCAN_OCTAVES,
)

__all__ = ["RootFinder", "RootSearchResult", "SearchAtDefaultRtol", "CEILING_RATIO", "CERTIFIED_STEP",
           "CIRCLE_MAX_POINTS", "CIRCLE_POINTS", "DEFAULT_SCALE", "DEFLATED_MAX_POINTS", "DEFLATED_POINTS", "FINE_SCAN_RATIO", "FIRST_CHUNK_RATIO",
           "FIRST_SEGMENT_RATIO", "FLOOR_CHECK", "FLOOR_MARGIN", "FLOOR_RATIO", "MAX_RTOL", "MAX_XTOL", "MIN_RTOL", "MIN_POINTS_PER_OCTAVE",
           "POINTS_PER_OCTAVE", "PREDICTION_MARGIN", "SCAN_OCTAVES"]
