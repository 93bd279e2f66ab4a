"""Natural frequencies of a model: topology → deduction → roots → result."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from linmstmm.deduction import Deduction
from linmstmm.model import Model
from linmstmm.roots import RootFinder
from linmstmm.topology import build_topology


@dataclass(frozen=True)
class FrequencyResult:
    """Elastic natural frequencies (Hz, ascending, repeated per multiplicity).

    rigid_body_modes : number of zero-frequency modes. ubar_order : order of
    Ū_all. seconds : wall time of the solve (loading excluded).
    precision : "float64" or "mpmath:<digits>".
    """

    model: str
    frequencies_hz: np.ndarray
    rigid_body_modes: int
    ubar_order: int
    seconds: float
    precision: str = "float64"

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
        }


def natural_frequencies(model: Model, count: int | None = 10, fmax: float | None = None,
                        digits: int | None = None, root: str | None = None) -> FrequencyResult:
    """Elastic natural frequencies of ``model`` by the transfer matrix method.

    count : the lowest N; fmax : Hz, all up to fmax; both: whichever stops first.
    root : boundary end (point name) to use as the root of the transfer tree.
    """
    start = time.perf_counter()
    deduction = Deduction(build_topology(model, root=root))
    finder = RootFinder(deduction.log_det, deduction.matrix)
    rigid = finder.rigid_body_modes()
    omega_max = None if fmax is None else 2 * np.pi * fmax
    roots = finder.find(count, omega_max)
    omegas = np.repeat([r.omega for r in roots], [r.multiplicity for r in roots])
    if count is not None:
        omegas = omegas[:count]
    return FrequencyResult(model.name, omegas / (2 * np.pi), rigid, deduction.order,
                           time.perf_counter() - start)
