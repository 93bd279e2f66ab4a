"""Natural frequencies of a model: topology → deduction → roots → result."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from linmstmm.deduction import Deduction
from linmstmm.model import Model
from linmstmm.roots import OMEGA_CEILING, RootFinder, release_indeterminate
from linmstmm.topology import build_topology


@dataclass(frozen=True)
class FrequencyResult:
    """Elastic natural frequencies (Hz, ascending, repeated per multiplicity).

    rigid_body_modes : number of zero-frequency modes. ubar_order : order of
    Ū_all as deduced. indeterminate_released : statically indeterminate
    unknowns (redundant rigid constraints) released before the root search.
    seconds : wall time of the solve (loading excluded).
    precision : "float64" or "mpmath:<digits>".
    """

    model: str
    frequencies_hz: np.ndarray
    rigid_body_modes: int
    ubar_order: int
    seconds: float
    precision: str = "float64"
    note: str = ""
    indeterminate_released: int = 0

    def to_dict(self) -> dict:
        """The ``linmstmm freqs --json`` object (``shared/spec/cli.md``)."""
        return {
            "model": self.model,
            "frequencies_hz": [float(f) for f in self.frequencies_hz],
            "rigid_body_modes": int(self.rigid_body_modes),
            "ubar_order": int(self.ubar_order),
            "seconds": float(self.seconds),
            "precision": self.precision,
            "method": "mstmm",
            "indeterminate_released": int(self.indeterminate_released),
            **({"note": self.note} if self.note else {}),
        }


def natural_frequencies(model: Model, count: int | None = 10, fmax: float | None = None,
                        digits: int | None = None, root: str | None = None) -> FrequencyResult:
    """Elastic natural frequencies of ``model`` by the transfer matrix method.

    count : the lowest N; fmax : Hz, all up to fmax; both: whichever stops first.
    root : boundary end (point name) to use as the root of the transfer tree.
    """
    start = time.perf_counter()
    deduction = Deduction(build_topology(model, root=root))
    released = release_indeterminate(deduction)
    finder = RootFinder(deduction.log_det, lambda omega: deduction.matrix(omega, stable=True)[0])
    rigid = finder.rigid_body_modes()
    omega_max = None if fmax is None else 2 * np.pi * fmax
    omegas = np.array(finder.find(count, omega_max))
    note = ""
    if count is not None and omegas.size < count and fmax is None:
        note = f"only {omegas.size} elastic natural frequencies exist below {OMEGA_CEILING:.3g} rad/s"
    return FrequencyResult(model.name, omegas / (2 * np.pi), rigid, deduction.full_order,
                           time.perf_counter() - start, note=note, indeterminate_released=released)
