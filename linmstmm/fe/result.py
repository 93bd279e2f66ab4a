"""The result of the finite-element route (:class:`FEResult`)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from linmstmm.results import Result, decode_array, encode_array


@dataclass(frozen=True, eq=False)
class FEResult(Result):
    """Natural frequencies by the finite-element route.

    frequencies_hz : (m,) elastic natural frequencies, ascending, Hz, each
        repeated per multiplicity.
    rigid_body_modes : number of zero-frequency modes (not in the list).
    error_estimate : (m,) estimated relative error of each frequency
        (discretisation and solver); NaN where it was not estimated
        (``estimate_error=False``; null in :meth:`to_dict`, and the note says so).
    elements_per_beam : finest mesh used (None for a model without beams).
    n_dof : reduced DOFs of that mesh. seconds : wall time of the whole solve.
    mode_shapes : (n_full, m) mass-normalised full vectors on that mesh (see
        :class:`DofIndex` for the layout), or None.
    note : empty, or, joined by "; ": the computed values not reported because
        their estimated relative error is UNSETTLED (10 %) or more, with all
        above them; the frequencies less accurate than asked where the
        refinement stopped at ``max_elements_per_beam`` with their estimated
        error above ``rtol``; that a model without beams has fewer elastic
        modes than asked for; that a fixed mesh holds fewer modes than asked
        for, or that its errors were not estimated.
    """

    model: str
    frequencies_hz: np.ndarray
    rigid_body_modes: int
    error_estimate: np.ndarray
    elements_per_beam: int | None
    n_dof: int
    seconds: float
    mode_shapes: np.ndarray | None = None
    note: str = ""

    kind = "fe"

    def to_dict(self) -> dict:
        """JSON-ready summary (the ``freqs --json`` keys plus the FE ones).

        Returns
        -------
        dict
            ``model``, ``frequencies_hz``, ``rigid_body_modes``, ``n_dof``, ``elements_per_beam``,
            ``error_estimate``, ``seconds``, ``method`` and, when set, ``note``.
        """
        return {"model": self.model,
                "frequencies_hz": [float(f) for f in self.frequencies_hz],
                "rigid_body_modes": int(self.rigid_body_modes),
                "n_dof": int(self.n_dof),
                "elements_per_beam": self.elements_per_beam,
                "error_estimate": [float(e) if np.isfinite(e) else None for e in self.error_estimate],
                "seconds": float(self.seconds),
                "method": "fe",
                **({"note": self.note} if self.note else {})}

    def _restoring_dict(self) -> dict:
        """The mode shapes :meth:`to_dict` leaves out (None when not computed)."""
        return {"mode_shapes": None if self.mode_shapes is None else encode_array(self.mode_shapes)}

    @classmethod
    def _from_data(cls, data: dict) -> FEResult:
        """The result :meth:`~linmstmm.results.Result.to_record` describes."""
        shapes = data["mode_shapes"]
        return cls(data["model"], decode_array(data["frequencies_hz"]), data["rigid_body_modes"],
                   decode_array(data["error_estimate"]), data["elements_per_beam"], data["n_dof"], data["seconds"],
                   None if shapes is None else decode_array(shapes, ndim=2), data.get("note", ""))

    def plot(self):
        """Draw the frequencies against their mode number and, on a second axis, their estimated errors.

        Returns
        -------
        matplotlib.figure.Figure
            Unsaved (:func:`linmstmm.plot.frequency_figure` with ``error_estimate``).
        """
        from linmstmm.plot import frequency_figure

        return frequency_figure(self.frequencies_hz, self.rigid_body_modes, self.error_estimate,
                                title=f"{self.model}: natural frequencies (finite elements)")
