"""The root search's settings: scan densities, point limits of the counts, and
the frequencies it decides by, each a multiple of the model's own frequency scale."""

from __future__ import annotations

import numpy as np

#: Grid points per octave of the scans (the fast path's above FINE_SCAN_RATIO × scale, an
#: eighth of it below; every segment's).
POINTS_PER_OCTAVE = 24
#: Coarser scans are refused. They were never faster: a coarse scan leaves
#: roots that the closing count finds missing, and the repairs cost more than
#: the scan saved. Measured on this machine before they were refused: MLRS 10 modes
#: 39 ms at 16, 52 ms at 12, 0.3–0.5 s at 4 and 2; the tip-mass cantilever
#: 40 modes 78 ms at 24, 158 ms at 20, 172 ms at 16; a 1000-beam chain
#: 3.3 s at 24, 6.6 s at 16; a 10,000-body spring chain 1.0–1.2 s at all.
MIN_POINTS_PER_OCTAVE = POINTS_PER_OCTAVE
#: A root whose last Newton step (its rounding floor in float64) was larger than this,
#: relative, is uncertified: checked on det itself (:meth:`RootFinder._checked`), and
#: refined in mpmath by ``natural_frequencies``.
CERTIFIED_STEP = 1e-9
#: Loosest accuracy (relative) a root may be certified to (RootFinder's ``rtol``):
#: roots are told apart down to RootFinder.SPLIT = 1e-4.
MAX_RTOL = 1e-4
#: Tightest: a hundred times float64's rounding floor of a root (the launcher's first
#: 20 are 6e-15 off at any setting). Roots float64 cannot bring within rtol are
#: refined in mpmath at 20 digits; tighter requests are ``digits``'.
MIN_RTOL = 1e-12
#: Loosest Newton tolerance (relative) RootFinder accepts: roots are told apart
#: down to SPLIT = 1e-4, so the polishing must be much tighter than that.
MAX_XTOL = 1e-6
#: Widest segment scanned in one grid, octaves (wider ones are split by a count).
SCAN_OCTAVES = 4
#: Every frequency the search decides by is a multiple of the model's own frequency
#: scale (:attr:`RootFinder.scale`, rad/s; :func:`linmstmm.solve.frequency_finder` takes
#: the lowest of :func:`linmstmm.nullspace.characteristic_frequencies`), so a model
#: written in mm or km, or a slow one, is searched alike. A scale of DEFAULT_SCALE
#: gives the absolute values (rad/s) the search was tuned with: floor 1e-3, first
#: chunk 8, fine scan from 1, first segment 2π, ceiling 1e9.
DEFAULT_SCALE = 10.0
#: Lowest scanned circular frequency (:attr:`RootFinder.floor`), times the scale.
FLOOR_RATIO = 1e-4
#: Top of the fast path's first chunk, times the scale.
FIRST_CHUNK_RATIO = 0.8
#: The fast path's scan takes points_per_octave above this (times the scale), an eighth below.
FINE_SCAN_RATIO = 0.1
#: Top of the segment search's first segment, times the scale.
FIRST_SEGMENT_RATIO = 2 * np.pi / DEFAULT_SCALE
#: The scan for ``count`` roots gives up above this (:attr:`RootFinder.ceiling`), times the scale.
CEILING_RATIO = 1e8
#: Where the lowest root found is below this many times the floor, a count in the disc
#: of the floor's radius checks that no elastic root hides below it (:meth:`RootFinder._check_floor`).
FLOOR_CHECK = 1e3
#: Predictions asked for beyond the count (plus a tenth of it): a coarse mesh can rank
#: a true root among the first N one or two places too high (the launcher's 100th).
PREDICTION_MARGIN = 2


def predictions_wanted(count: int) -> int:
    """How many predictions a search for the lowest ``count`` roots asks for: PREDICTION_MARGIN
    and a tenth of ``count`` beyond it.

    Parameters
    ----------
    count : int
        Roots wanted.

    Returns
    -------
    int
    """
    return count + PREDICTION_MARGIN + count // 10


#: Predictions whose lowest is below this many times the floor are not used (the scan
#: from the floor searches instead): with an absolute floor of 1e-3 rad/s a free strip
#: 9.9 m long with Iz = 1e-12 m⁴ (first bending mode 1.4e-3 rad/s) was refused; the
#: floor now follows the beam's own scale and it is found.
FLOOR_MARGIN = 5.0
#: Starting points of a half-ellipse count with the known roots divided out.
DEFLATED_POINTS = 9
#: Starting points of a count over a small circle (a multiplicity).
CIRCLE_POINTS = 9
#: Points a count over a small circle may take before it fails. One root of
#: multiplicity m turns the phase by mπ; the test suite's circles (NAFEMS FV2's
#: sevenfold roots among them) took at most 41. Around "roots" Newton settled on
#: where det is rounding noise they refine until this: random ring 5 up to 1e9 Hz,
#: 125 circles in one count, ran out of memory at 117,000 points a round with the
#: general limit.
CIRCLE_MAX_POINTS = 200
#: Points a count with the known roots divided out may take before it fails. Such a
#: phase hardly turns: the fast path's took at most 423 on 40 random models at 80 modes
#: (before each point carried its derivative, at twice the evaluations: half as many now).
#: One that did not settle took 20,000 (the limit then) twice over, and random
#: floating_loops 70 at 80 modes spent 100 s on it before the segment search found
#: all 80 in 2 s.
DEFLATED_MAX_POINTS = 1000
