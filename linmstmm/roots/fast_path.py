"""The fast path of the search: scan ahead from the floor until enough candidates
are seen, polish them all at once, and keep them if one closing count agrees;
else look for the missing roots in the stored scan and by deflated counts."""

from __future__ import annotations

import numpy as np

from linmstmm.counting import deflated, divided_out, zero_free
from linmstmm.roots.brackets import quiet_minima
from linmstmm.roots.settings import DEFLATED_POINTS, FINE_SCAN_RATIO, FIRST_CHUNK_RATIO


def scan_ahead(finder, count: int | None, omega_max: float | None):
    """Guess, polish, confirm: the fast path of :meth:`find`, or None.

    A coarse scan (``points_per_octave`` above FINE_SCAN_RATIO × scale, an eighth
    of it below) goes up in chunks (to FIRST_CHUNK_RATIO × scale, then up to ×4 each, less where
    the candidates so far extrapolate to ``count`` sooner: :meth:`_next_top`;
    see :meth:`_scanned`)
    until it has seen ``count`` candidates (sign changes, and minima of
    log|det| without one), reached ``omega_max``, or scanned a chunk
    without a new candidate; all are polished at once (more chunks if their
    multiplicities leave fewer than ``count`` roots) and one count from
    the floor must agree. Multiplicities are
    read from the pencil offsets; those above one are counted over a circle
    first (a spurious one would cancel a missing root in that count), and a
    simple one misread changes the total, which that count sees. If the count
    finds more, the repairs of :meth:`_closed` follow (the deferred cluster
    members, the stored scan with the found roots divided out, deflated
    counts, recounted multiplicities), each
    followed by the closing count again. Far fewer
    evaluations than the segment search when it works; when it does not
    (a root between two candidates, a chain of clusters), :meth:`find`
    falls back.
    """
    found: list[float] = []
    finder.deferred_members, finder.left_out, finder.root_free_below = [], [], finder.floor
    brackets, minima = [], []  # (lo, hi, log|det(hi)| − log|det(lo)|) and grid points
    lo, hi = finder.floor, FIRST_CHUNK_RATIO * finder.scale
    scans = [(np.zeros(0),) * 3]  # every chunk's (grid, sign, log|det|), kept for _rescanned
    while True:
        if omega_max is not None:
            hi = min(hi, omega_max)
        grid, sign, log_abs = scan = finder._scanned(lo, hi, scans[-1])
        scans.append(scan)
        change = np.flatnonzero(sign[:-1] * sign[1:] < 0)
        change = change[grid[change + 1] > lo]  # (the lower chunk's own were taken there)
        waiting = len(brackets) + len(minima)
        brackets += zip(grid[change], grid[change + 1], log_abs[change + 1] - log_abs[change])
        minima += list(grid[quiet_minima(sign, log_abs)])
        # A chunk with few new candidates (a quarter of those seen, or none) after some:
        # polish those; their multiplicities (a chain's triple roots are one sign change
        # each) and the close pairs their pencils point at (no sign change where both
        # share a scan step) may make up the count, where scanning on for more would
        # polish roots far above it (MLRS 40 modes: up to 240 Hz for a 43.5 Hz count).
        new = len(brackets) + len(minima) - waiting
        stalled = count is not None and waiting > 0 and new <= (len(found) + waiting) / 4
        if (omega_max is not None and hi >= omega_max or stalled
                or count is not None and len(found) + len(brackets) + len(minima) >= count):
            if count is not None:  # only the lowest candidates matter
                keep = sorted([(b[0], b) for b in brackets] + [(m, None) for m in minima])[:count - len(found)]
                brackets = [b for _, b in keep if b is not None]
                minima = [m for m, b in keep if b is None]
            found = finder._polished(minima, found, confirm=False)
            if brackets:
                found = finder._with_groups(found, finder._bracketed(*map(np.array, zip(*brackets)), confirm=False,
                                                                 needed=count, known=found))
            brackets, minima = [], []
            if count is not None and found and len(found) < count:  # pairs hidden in one scan step?
                found = finder._with_members(found, found[-1])
            if count is not None and len(found) < count and finder.left_out:  # each holds a root
                found = finder._with_left_out(found, count - len(found))
            if omega_max is not None and hi >= omega_max or count is not None and len(found) >= count:
                return finder._closed(found, count, omega_max, scans)
        # fewer roots than count? (sign changes only: a shallow quiet minimum far
        # below the first root is no evidence that the roots have run out)
        seen = found + [b[0] for b in brackets]
        if omega_max is None and (hi >= finder.ceiling or (seen and hi > 1e3 * max(seen))):
            return None
        lo, hi = hi, finder._next_top(hi, sorted(seen + minima), count)


def closed(finder, found: list[float], count: int | None, omega_max: float | None, scans):
    """``found`` as the closing count confirms it (:meth:`_confirmed`), after the
    repairs it takes, each followed by that count again; None if none is enough.

    Every closing count first has the multiplicities above one inside it
    counted over circles (:meth:`_settled`). The repairs:

    1. The deferred cluster members polished (:meth:`_with_members`: a close
       pair's other member, which the pencil at the found one points at).
    2. The roots the scan's own values show once ``found`` is divided out
       (:meth:`_rescanned`; no new scan): two roots in one grid step, one of
       them found.
    3. The roots still missing, located by deflated counts (:meth:`_recovered`),
       below the count's top or, with fewer than ``count`` found, below the
       highest root found.
    4. Every multiplicity recounted: one read as simple may be double. Last,
       as the rarest and dearest: a circle's count per root (MLRS 50 modes:
       850 contour points, 1 s, where the recovery alone was enough).

    All look only below the closing count's top (the scan may have gone far
    past the count-th root: a 40-mode beam's recount of all it saw cost 1000
    contour points).
    """
    def top(roots):
        return finder._count_top(roots, count, omega_max) or np.inf

    found = finder._settled(found, count, omega_max)
    confirmed = finder._confirmed(found, count, omega_max)
    for repair in (lambda roots: finder._with_members(roots, top(roots)),
                   lambda roots: finder._rescanned(roots, scans, top(roots))):
        if confirmed is not None:
            break
        repaired = repair(found)
        if repaired != found:
            found = repaired
            confirmed = finder._confirmed(found, count, omega_max)
    upper = None
    if confirmed is None and found:  # with fewer than count found (misread multiplicities
        # recounted), the missing may still be below the highest: look there
        upper = finder._count_top(found, count, omega_max) or found[-1] * (1 + finder.CLUSTER_WINDOW)
    if upper is not None:
        found, cap = finder._recovered(found, upper, count)
        confirmed = finder._confirmed(found, count, omega_max, cap)
        if confirmed is None:
            recounted = finder._recounted(found, [r for r in sorted(set(found)) if r < min(top(found), cap)])
            confirmed = None if recounted == found else finder._confirmed(recounted, count, omega_max, cap)
    return confirmed


def with_members(finder, found: list[float], upper: float) -> list[float]:
    """``found`` with the roots Newton reaches from the :attr:`deferred_members` below
    ``upper``, which leave the list: not those within SPLIT of a root found (Newton
    would return to it) or of a lower start (the same root)."""
    starts = finder._member_starts(found, upper)
    finder.deferred_members = [member for member in finder.deferred_members if member[0] >= upper]
    return finder._polished(starts, found, confirm=False) if starts else found


def with_left_out(finder, found: list[float], missing: int) -> list[float]:
    """``found`` with the roots of the lowest ``missing`` :attr:`left_out` brackets,
    which leave the list: where the found roots and the members fell short of the
    count that left them out, each is a root the count may need (left for the scan
    to go on, random ring 3 at 80 modes was scanned up to 1e9 rad/s, its new
    brackets left out each time). The others stay out: the roots missing may be
    lower (pairs hidden in a scan step), for the closing count to find."""
    finder.left_out.sort()
    lo, hi = map(np.array, zip(*finder.left_out[:missing]))
    finder.left_out = finder.left_out[missing:]
    return finder._with_groups(found, finder._narrowed_groups(lo, hi, [found], confirm=False))


def member_starts(finder, found: list[float], upper: float = np.inf) -> list[float]:
    """The :attr:`deferred_members` below ``upper`` that may lead to a root not in
    ``found``: not those within SPLIT of a root found (Newton would return to it)
    or of a lower start (the same root), ascending."""
    starts: list[float] = []
    for start, origin in sorted(finder.deferred_members):
        near = finder.MEMBER_OVERLAP * abs(start - origin)
        if start < upper and all(abs(start - r) > max(finder.SPLIT * r, near * (r != origin))
                                 for r in found + starts[-1:]):
            starts.append(start)
    return starts


def rescanned(finder, found: list[float], scans, upper: float = np.inf) -> list[float]:
    """``found`` with the roots below ``upper`` that the fast scan's values (``scans``:
    (grid, sign, log|det|) per chunk) show once ``found`` is divided out (:func:`divided_out`).

    Two roots in one grid step give det no sign change there, nor does a
    root hidden beside a found one; the deflated det changes sign at the
    missing one. Only values already computed are looked at; the
    candidates are then handled as in :meth:`_recovered`. A root found so
    can hide the next one in the same step: up to RESCANS passes, while
    each finds more.
    """
    grid, sign, log_abs = (np.concatenate(parts) for parts in zip(*scans))
    grid, first = np.unique(grid, return_index=True)
    first = first[:np.searchsorted(grid, upper) + 1]  # the step across upper too
    grid, sign, log_abs = grid[:first.size], sign[first], log_abs[first]
    for _ in range(finder.RESCANS if grid.size >= 3 else 0):
        more = finder._deflated_candidates(found, [grid], *divided_out(grid, sign, log_abs, found),
                                         deflated(finder.log_det, found))
        if more == found:
            break
        found = more
    return found


def deflated_candidates(finder, found: list[float], grids, sign, log_abs, reduced) -> list[float]:
    """``found`` with the roots in the sign changes and quiet minima of a deflated scan:
    ``grids`` (ascending arrays) with the (phase, log|·|) of ``reduced`` (deflated
    det) at their points, concatenated. A sign change is narrowed to xtol by
    regula falsi on ``reduced`` (a missing root may share a grid step with a
    found one, where Newton would return to that); a minimum is polished."""
    brackets, minima = [], []
    for grid, piece_sign, piece_log in zip(grids, *(np.split(v, np.cumsum([g.size for g in grids])[:-1])
                                                     for v in (np.real(sign), log_abs))):
        change = np.flatnonzero(piece_sign[:-1] * piece_sign[1:] < 0)
        brackets += zip(grid[change], grid[change + 1])
        minima += list(grid[quiet_minima(piece_sign, piece_log)])
    found = finder._polished(minima, found, confirm=False)
    if not brackets:
        return found
    return finder._with_groups(found, [[root] for root in finder._bracket_roots(*map(np.array, zip(*brackets)),
                                                                              log_det=reduced)])


def scanned(finder, lo: float, hi: float, below) -> tuple:
    """(grid, sign, log|det|) of the fast scan over [lo, hi], led by the last two
    points of ``below`` (the chunk under it, same form): a sign change or a
    quiet minimum at the edge between two chunks is seen (a double root of a
    round tube 1 % below a chunk's top was missed), and lo is not evaluated
    twice. The first chunk, 13 octaves from the floor that hold no root in
    most models, is left out if a cheap count finds none there (and
    :attr:`root_free_below` says so)."""
    tail = tuple(part[-2:] for part in below)
    if lo == finder.floor and finder._holds_no_roots(lo, hi):
        finder.root_free_below = hi
        return tail
    grid = finder._quick_grid(lo, hi)
    grid = grid[1:] if tail[0].size and grid[0] == tail[0][-1] else grid
    sign, log_abs = finder.log_det(grid)
    return np.r_[tail[0], grid], np.r_[tail[1], sign], np.r_[tail[2], log_abs]


def holds_no_roots(finder, lo: float, hi: float) -> bool:
    """True if a count over (lo, hi) from DEFLATED_POINTS starting points finds
    no root (False also when it cannot count, and without counting where det has
    opposite signs at lo and hi: :func:`~linmstmm.counting.zero_free`)."""
    return zero_free(finder.log_det, lo, hi, initial_points=DEFLATED_POINTS)


def quick_grid(finder, lo: float, hi: float) -> np.ndarray:
    """The fast path's scan of [lo, hi]: points_per_octave above FINE_SCAN_RATIO × scale,
    an eighth below."""
    def geometric(a, b, per_octave):
        return np.geomspace(a, b, 1 + int(np.ceil(per_octave * np.log2(b / a)))) if b > a else np.zeros(0)
    fine = FINE_SCAN_RATIO * finder.scale
    return np.unique(np.r_[geometric(lo, min(hi, fine), finder.points_per_octave / 8),
                           geometric(max(lo, fine), hi, finder.points_per_octave)])
