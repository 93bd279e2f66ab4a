"""What one root search returns (:class:`RootSearchResult`): the roots and the
search's diagnostics, frozen as the search ends, so that nothing a later search
on the same :class:`~linmstmm.roots.RootFinder` does can change them."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np


@dataclass(frozen=True, eq=False)
class RootSearchResult:
    """The elastic roots of det Ū_all one search found, and how it found them.

    Immutable: assigning an attribute raises ``FrozenInstanceError``, the
    array is not writeable and the mappings are read-only views of copies
    made at construction.

    Attributes
    ----------
    roots : numpy.ndarray, shape (n,)
        Elastic natural frequencies, rad/s, ascending, each repeated per
        multiplicity; read-only.
    multiplicities : Mapping[float, int]
        Each distinct root (rad/s) -> how often ``roots`` holds it. A root cut
        by the search's ``count`` holds only the copies within the count (its
        whole multiplicity: :meth:`~linmstmm.roots.RootFinder.multiplicity`).
    last_steps : Mapping[float, float]
        Each distinct root (rad/s) -> the relative size |Δω|/ω of the last
        Newton step that reached it (of a narrowed bracket: its relative
        width); above the finder's ``rtol`` (by default
        :data:`~linmstmm.roots.CERTIFIED_STEP`) the root is uncertified in float64. NaN for a root no step reached, placed by a
        count alone (it is in ``unseparated``).
    unseparated : Mapping[float, tuple[int, float]]
        Each root (rad/s) of ``roots`` that stands for several float64 could
        not tell apart or locate -> (multiplicity, radius rad/s of the
        interval a count encloses them in), ascending.
    note : str
        Why the search stopped short of what was asked; "" if it did not.
    rigid_body_modes : int
        Number of zero-frequency modes, not among ``roots``.
    evaluations : int or None
        Float64 evaluations of det Ū_all this search spent (for a finder's
        first search, with those of the finder's own preparation, such as
        its rigid-body check); None where the finder has no determinant
        that counts them.
    ceiling : float
        rad/s: the frequency above which a search for a count of roots gives up.
    """

    roots: np.ndarray
    multiplicities: Mapping[float, int]
    last_steps: Mapping[float, float]
    unseparated: Mapping[float, tuple[int, float]]
    note: str
    rigid_body_modes: int
    evaluations: int | None
    ceiling: float

    def __post_init__(self):
        roots = np.array(self.roots, dtype=float)
        roots.setflags(write=False)
        object.__setattr__(self, "roots", roots)
        for name in ("multiplicities", "last_steps", "unseparated"):
            object.__setattr__(self, name, MappingProxyType(dict(getattr(self, name))))


def search_result(finder, roots: list[float]) -> RootSearchResult:
    """The frozen result of the search of ``finder`` that found ``roots``.

    Parameters
    ----------
    finder : RootFinder
        The finder whose search just ended (its diagnostics are read now).
    roots : list of float
        rad/s, ascending, each repeated per multiplicity: what the search found.

    Returns
    -------
    RootSearchResult
        Its ``evaluations`` are those of ``finder.determinant`` since the
        finder's previous search ended (since the determinant was made, for
        the first).
    """
    tally = Counter(map(float, roots))
    distinct, steps = sorted(tally), finder.last_step
    counter = finder.determinant
    evaluations = None if counter is None else counter.evaluations - finder._evaluations_reported
    if counter is not None:
        finder._evaluations_reported = counter.evaluations
    return RootSearchResult(
        roots=roots,
        multiplicities={root: tally[root] for root in distinct},
        last_steps={r: steps.get(r, np.nan) for r in distinct},
        unseparated=finder.unseparated_among(distinct),
        note=finder.note,
        rigid_body_modes=finder.rigid_body_modes(),
        evaluations=evaluations,
        ceiling=finder.ceiling,
    )
