"""A lower bound on how many natural frequencies lie below a frequency, from the beams alone.

Wittrick and Williams (1971): the number of natural frequencies below ω is
J(ω) = J0(ω) + s{K(ω)}, where J0 sums, over the elements, the natural
frequencies below ω of each element with both ends clamped, and s{K} (the
negative eigenvalues of the dynamic stiffness matrix) is never negative. So
J0 bounds J from below, and needs nothing but each beam's data: a request
for every frequency up to some fmax can be refused before the search starts
when J0 alone is too many (a beam has infinitely many; ``--fmax 1e30`` searched
without end). J0 is counted exactly by
:func:`linmstmm.dynamic_stiffness.clamped_counts`; the whole count J is
:mod:`linmstmm.wittrick_williams`.
"""
from __future__ import annotations

import math

from linmstmm.dynamic_stiffness import BeamTable, clamped_counts
from linmstmm.model import Model, ModelError

#: A request for every frequency up to fmax is refused when the beams' clamped-end
#: modes alone put more than this many below it (300 modes of the bundled
#: cantilever took 6.6 s, and the time grows faster than the count).
MAX_RANGE_MODES = 1000


def clamped_modes_below(model: Model, omega: float) -> int:
    """J0(ω): the clamped–clamped natural frequencies of all beams below ``omega``
    (rad/s), exactly where float64 can place ω among them, one fewer per family
    where it cannot (at one of them, or at 1e30 Hz): a lower bound on the model's."""
    return clamped_counts(BeamTable.of(model.beams), omega, at_least=True)


def check_range_request(model: Model, fmax: float, request: str | None = None,
                        instead: str = "ask for a lower fmax, or for the lowest N by count") -> None:
    """Raise ModelError if every frequency up to ``fmax`` (Hz) is asked for and
    :func:`clamped_modes_below` puts more than MAX_RANGE_MODES there, or fmax is not
    a positive finite number. request : how the message names the request
    (default ``fmax = … Hz``); instead : what it advises."""
    where, request = model.source or model.name, request or f"fmax = {fmax:g} Hz"
    if not (math.isfinite(fmax) and fmax > 0):
        raise ModelError(where, f"{request}: must be a positive finite frequency")
    at_least = clamped_modes_below(model, 2 * math.pi * fmax)
    if at_least > MAX_RANGE_MODES:
        raise ModelError(where, f"{request}: at least {at_least} natural frequencies lie below {fmax:g} Hz "
                                f"(the beams' clamped-end modes alone); a range is searched for at most "
                                f"{MAX_RANGE_MODES}: {instead}")
