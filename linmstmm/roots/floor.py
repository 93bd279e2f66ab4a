"""The floor of the search: predictions too close to it are not used, and no
elastic root may hide below it (a count in the disc of its radius)."""

from __future__ import annotations

import numpy as np

from linmstmm.counting import count_in_disc
from linmstmm.roots.settings import FLOOR_CHECK, FLOOR_MARGIN


def separated_above_floor(finder, found: list[float]) -> list[float]:
    """``found`` (rad/s) with each multiple root that is a cluster split into its roots
    (:meth:`_separated`), then checked for roots below the floor (:meth:`_check_floor`)."""
    found = finder._separated(found)
    finder._check_floor(found)
    return found


def usable(finder, predictions: np.ndarray) -> bool:
    """False where the lowest prediction (rad/s) is below FLOOR_MARGIN floors: the
    coarse model's eigenvalues there are rounding of its stiffest ones (a strip with
    bending stiffnesses 1e10 apart predicted 0 Hz), and the scan from the floor
    decides instead (:meth:`_check_floor` says so if a root lies below it)."""
    return not (predictions.size and predictions[0] < FLOOR_MARGIN * finder.floor)


def check_floor(finder, found: list[float]) -> None:
    """Raise RuntimeError if det has zeros below the floor besides the rigid-body
    modes' (every count starts there, so such roots would be missing from the
    list without a word: a cantilever with Iy = 1e-20 m⁴ has its first four
    between 1.5e-6 and 7e-5 Hz). Checked with one count in that disc, only where
    the lowest root found is within FLOOR_CHECK times the floor."""
    if not found or found[0] > FLOOR_CHECK * finder.floor:
        return
    expected = 0 if finder._divided else 2 * finder._rigid
    try:
        below = count_in_disc(finder.log_det, finder.floor)
    except RuntimeError:
        below = None
    if below != expected:
        raise RuntimeError(f"det Ū_all has zeros below {finder.floor:.3g} rad/s "
                           f"({finder.floor / (2 * np.pi):.3g} Hz) besides the rigid-body modes', which "
                           "the root search cannot certify: use `linmstmm fe` for this model")
