"""Predictions of one multiple root: which coincide (:func:`coincident`), and how a
search without a Wittrick–Williams counter finds the other members of the root it
polishes from such a group (:func:`other_members`). Used by :mod:`linmstmm.predicted`."""
from __future__ import annotations

import numpy as np

from linmstmm.prediction_groups import cluster_reach, near_any

#: Predictions this close (relative) are one multiple root's where the search has a
#: Wittrick–Williams counter (:func:`coincident`): the dense coarse eigensolve gives a
#: symmetric structure's multiple roots to the last digits.
COINCIDENT = 1e-10
#: Predictions closer than this (relative) may be one multiple root's, as far as a
#: prediction can tell: the Lanczos's Ritz values of a double root lay up to 1.7e-8
#: apart (a round cantilever of 1,000 beams), 7.4e-7 on 3,300 beams written in kg and km
#: (the factorisation's rounding grows as the fourth power of the beams), the dense
#: route's 7e-9. A search without a Wittrick–Williams counter polishes such a group as
#: one root and finds its other members from there (:func:`other_members`).
COINCIDING = 3e-6


def coincident(predictions: np.ndarray, indices: np.ndarray, counted: bool) -> tuple[np.ndarray, np.ndarray]:
    """(leaders, followers): of ``indices``, those whose prediction equals the next one's
    (to COINCIDENT for a search with a Wittrick–Williams counter, ``counted``, else to
    COINCIDING), first of each such group, and the others of the group.

    A symmetric structure's coarse model predicts its multiple roots as equal values
    (a steel rod with Iy = Iz: its bending roots to the last digit). The secant on
    det creeps to a multiple root, where det keeps its sign, and a value that
    coincides with another prediction never stands (half the gap to it is zero):
    the secant spent its twelve steps on each member in vain, 24 evaluations a
    double root. A leader goes to Newton on the pencil, which converges to a
    multiple root as fast as to a simple one; its followers go to the
    Wittrick–Williams counts around it, which give its multiplicity, or without a
    counter to :func:`other_members`."""
    if indices.size < 2:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    values = predictions[indices]
    same = np.diff(values) <= (COINCIDENT if counted else COINCIDING) * values[1:]
    follows = np.r_[False, same]
    leads = np.r_[same, False] & ~follows
    return indices[leads], indices[follows]


def other_members(finder, roots: list[float], predictions: np.ndarray, leaders: np.ndarray,
                  followers: np.ndarray) -> tuple[list[float], np.ndarray]:
    """(``roots`` (rad/s) with the other members of each group of coincident predictions
    found, the ``followers`` left): for a search without a Wittrick–Williams counter
    (with one, the counts across each root give its multiplicity,
    :func:`~linmstmm.predicted._completed_by_counts`).

    A group (a leader of :func:`coincident` and its followers) whose leader's
    prediction has one root of ``roots`` within :func:`~linmstmm.prediction_groups.cluster_reach`
    takes as its other members first the distinct roots the pencil's offsets there lead
    Newton to (:meth:`RootFinder.beside`: a pair 1e-6 apart), else that root again as
    often as the count over its tight circle finds more roots there
    (:meth:`RootFinder.tight_counts`, all circles in one count; the count
    :meth:`RootFinder._separated` asks of every multiple root anyway), where that
    accounts for all its followers. The followers of a group this does not settle are
    polished one by one, as a close pair's members are (:func:`~linmstmm.predicted._deflated_polished`). In
    the segment search a round cantilever of 100 beams' double roots took 560 of the
    790 evaluations its ten lowest cost from their predictions, where the scan took
    635; pairs 1e-6 to 3e-6 apart took it 8,000 to 44,000. A circle count is
    independent of the certifying count over the whole range, in which a root divided
    out once too often would cancel one missed elsewhere."""
    if not followers.size:
        return roots, followers
    group_of = np.searchsorted(leaders, followers) - 1  # a group's followers come right after its leader
    centres, groups = [], []
    for k, leader in enumerate(leaders.tolist()):
        members = followers[group_of == k].tolist()
        reach = cluster_reach(predictions, float(predictions[leader]))
        near = {r for r in roots if abs(r - predictions[leader]) <= reach}
        if members and len(near) == 1 and roots.count(min(near)) == 1:
            centres.append(min(near))
            groups.append(members)
    shared = {c for c in centres if centres.count(c) > 1}  # two groups near one root: neither is settled here
    groups = [members for c, members in zip(centres, groups) if c not in shared]
    centres = [c for c in centres if c not in shared]
    if not centres:
        return roots, followers
    offsets = finder.offsets_of(centres, [1] * len(centres))
    partners = finder.beside([(c, offsets[c]) for c in centres])
    roots, settled, alone = list(roots), set(), []
    for centre, members, beside in zip(centres, groups, partners):
        beside = [r for r in beside if not near_any(r, roots, finder.same_root)]
        if len(beside) == len(members):
            roots += beside
            settled.update(members)
        elif not beside:
            alone.append((centre, members))
    if alone:
        counts, radii = finder.tight_counts([c for c, _ in alone], sorted(set(roots)))
        for (centre, members), count, radius in zip(alone, counts, radii):
            if count == len(members) + 1:
                roots += [centre] * len(members)
                settled.update(members)
                finder._counted[centre], finder._circles[centre] = count, radius  # the certifying count's check
    return roots, np.array([j for j in followers.tolist() if j not in settled], dtype=followers.dtype)
