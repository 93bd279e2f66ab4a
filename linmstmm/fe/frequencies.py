"""Natural frequencies with mesh refinement and error estimates
(:func:`fe_frequencies`): fixed mesh or mesh doubling with Richardson
extrapolation, values whose own error estimate is too large left out."""
from __future__ import annotations

from time import perf_counter

import numpy as np

from linmstmm.fe.assembly import assemble
from linmstmm.fe.eigensolver import fe_modes
from linmstmm.fe.elements import dispersion_error
from linmstmm.fe.result import FEResult
from linmstmm.fe.richardson import _extrapolate
from linmstmm.mode_bound import check_range_request
from linmstmm.model import Model
from linmstmm.threads import one_blas_thread
from linmstmm.wording import counted

#: A frequency whose estimated relative error is at or above this is not
#: reported (its own estimate leaves not even its first digit assured).
UNSETTLED = 0.1
#: Floor of every relative error estimate of λ (rounding of the last digits).
ROUNDOFF = 4 * np.finfo(float).eps
_TWO_PI = 2.0 * np.pi


def fe_frequencies(model: Model, count=10, fmax=None, elements_per_beam=None,
                   rtol: float = 1e-9, *, estimate_error: bool = True,
                   max_elements_per_beam: int = 1024, mode_shapes: bool = False) -> FEResult:
    """Elastic natural frequencies of ``model`` by finite elements.

    Parameters
    ----------
    model : Model
        The model.
    count : int or None
        The lowest ``count`` frequencies.
    fmax : float or None
        All frequencies up to ``fmax`` Hz. Both: whichever stops first;
        neither: ``count = 10``.
    elements_per_beam : int or None
        None = refine: double the mesh from 4 elements per beam,
        Richardson-extrapolate each frequency, and stop when every estimated
        relative error is <= ``rtol`` (at least three meshes) or the next
        mesh would exceed ``max_elements_per_beam``. An int = that mesh, no
        extrapolation; its error is estimated from one solve on half the mesh
        (on twice the mesh for a mode half the mesh does not have, and for one
        element per beam) unless ``estimate_error`` is False (then NaN, and
        the note says the frequencies are unchecked).
    rtol : float
        Target relative error of the frequencies when refining.
    estimate_error : bool
        With a fixed mesh: estimate the error from another mesh.
    max_elements_per_beam : int
        The finest mesh the refinement may reach.
    mode_shapes : bool
        Also return mass-normalised full mode vectors.

    Returns
    -------
    FEResult

    Zero-frequency rigid-body modes are counted structurally (see the notes
    of :mod:`linmstmm.fe`), not by a threshold on computed eigenvalues. No value whose estimated
    relative error is UNSETTLED (10 %) or more is reported as a frequency, nor
    any above it: the result stops before it and its note names them. ``fmax`` alone is checked
    as :func:`linmstmm.solve.natural_frequencies` checks it (ModelError).

    BLAS runs on one thread here (:mod:`linmstmm.threads`) unless the model has more
    than THREADED_NODES nodes: on a busy two-core machine the launcher's ten lowest
    took 2.2 s with OpenBLAS's two threads, waking for small products and ARPACK's
    vector operations, and 0.14 s with one.
    """
    arguments = (model, count, fmax, elements_per_beam, rtol, estimate_error, max_elements_per_beam, mode_shapes)
    if len(model.points) + len(model.rigids) > THREADED_NODES:
        return _frequencies(*arguments)
    with one_blas_thread():
        return _frequencies(*arguments)


#: Nodes (points and mass centres) above which :func:`fe_frequencies` keeps the machine's
#: BLAS threads. Measured on an idle two-core machine, one thread against two: as fast
#: for spring–mass chains up to 3,000 bodies (9,000 unknowns), twice as fast on the
#: launcher's 100 lowest (meshes up to 6,204 unknowns: 1.5 s against 3.1 s), and slower
#: only on the 10,000-body chain (30,000 unknowns: 1.19 s against 0.80 s).
THREADED_NODES = 5000


def _frequencies(model, count, fmax, elements_per_beam, rtol, estimate_error, max_elements_per_beam,
                 mode_shapes) -> FEResult:
    """:func:`fe_frequencies` on the BLAS threads it chose."""
    started = perf_counter()
    if count is None and fmax is None:
        count = 10
    if count is None:
        check_range_request(model, fmax)
    lam_max = None if fmax is None else (_TWO_PI * fmax) ** 2
    if not model.beams:
        fe = assemble(model, 1)
        lam, X, lam_error = fe_modes(fe, count, lam_max)
    elif elements_per_beam is not None:
        fe, lam, X, lam_error = _fixed_mesh(model, elements_per_beam, count, lam_max,
                                            estimate_error)
    else:
        fe, lam, X, lam_error = _refine(model, count, lam_max, rtol, max_elements_per_beam)
    keep = np.ones(len(lam), bool) if lam_max is None else lam <= lam_max
    lam, X, lam_error = lam[keep][:count], X[:, keep][:, :count], lam_error[keep][:count]
    order = np.argsort(lam)
    frequencies_hz, error_estimate = np.sqrt(lam[order]) / _TWO_PI, np.maximum(lam_error[order], ROUNDOFF) / 2
    refined = bool(model.beams) and elements_per_beam is None
    if refined:
        error_estimate = _with_dispersion(model, fe.elements_per_beam, frequencies_hz, error_estimate, rtol)
    settled = _settled_count(error_estimate)
    notes = [_unsettled(frequencies_hz[settled:], error_estimate[settled:])]
    frequencies_hz, error_estimate, order = frequencies_hz[:settled], error_estimate[:settled], order[:settled]
    if refined:
        notes.append(_short_of_rtol(frequencies_hz, error_estimate, rtol, fe.elements_per_beam))
    elif model.beams:
        notes.append(_fixed_mesh_note(fe, len(lam), count if fmax is None else None, error_estimate))
    if not model.beams and fmax is None and len(lam) < count:
        notes.append(f"only {counted(len(lam), 'elastic natural frequency exists', 'elastic natural frequencies exist')}"
                     f" (directions with mass less the {counted(fe.rigid_modes.shape[1], 'rigid-body mode')})")
    return FEResult(model=model.name,
                    frequencies_hz=frequencies_hz,
                    rigid_body_modes=fe.rigid_modes.shape[1],
                    error_estimate=error_estimate,
                    elements_per_beam=fe.elements_per_beam if model.beams else None,
                    n_dof=fe.n_dof,
                    seconds=perf_counter() - started,
                    mode_shapes=(fe.T @ X[:, order]) if mode_shapes else None,
                    note="; ".join(note for note in notes if note))


def _settled_count(error_estimate) -> int:
    """How many of the ascending frequencies are reported: those before the first
    whose estimated relative error is UNSETTLED or more. The ones above it are not
    reported either, since a list with a gap would misstate their ranks. A NaN
    estimate (not asked for) does not stop the list."""
    unsettled = np.flatnonzero(error_estimate >= UNSETTLED)
    return int(unsettled[0]) if len(unsettled) else len(error_estimate)


def _unsettled(frequencies_hz, error_estimate) -> str:
    """The note naming frequencies left out of a result (empty if none is)."""
    if not len(frequencies_hz):
        return ""
    listed = ", ".join(f"{f:.6g} Hz ({e:.1e})" for f, e in zip(frequencies_hz[:5], error_estimate[:5]))
    more = f" and {len(frequencies_hz) - 5} more" if len(frequencies_hz) > 5 else ""
    return (f"{counted(len(frequencies_hz), 'computed value')} not reported as frequencies, from the first whose "
            f"estimated relative error is {UNSETTLED:.0%} or more: {listed}{more}")


def _with_dispersion(model, elements_per_beam, frequencies_hz, error_estimate, rtol):
    """``error_estimate`` with those above ``rtol`` (a refinement stopped at its mesh
    cap) raised to the elements' dispersion error on the finest mesh at their
    frequency, the largest over the beams (:func:`dispersion_error`).

    Modes are matched by rank across meshes. A mode that converges too slowly
    to settle by the cap (a high torsion mode of linear elements) can rank above
    its true place on every mesh, so that the rank it should hold is held by the
    next mode up and the extrapolation is of the wrong mode, with a small change
    between meshes: random ring 2 at 120 modes reported its 120th frequency 8.5e-4
    off with an estimate of 1.5e-5. The reported value is then off by at most the
    hidden mode's own error, which the dispersion error of the finest mesh bounds.
    """
    short = error_estimate > rtol
    if not short.any():
        return error_estimate
    dispersion = [max(dispersion_error(beam, beam.length / elements_per_beam, _TWO_PI * f) for beam in model.beams)
                  for f in frequencies_hz[short]]
    raised = error_estimate.copy()
    raised[short] = np.maximum(error_estimate[short], dispersion)
    return raised


def _short_of_rtol(frequencies_hz, error_estimate, rtol, elements_per_beam) -> str:
    """The note of a refinement that stopped at its mesh cap with estimates above ``rtol``
    (empty if none is)."""
    short = np.flatnonzero(error_estimate > rtol)
    if not len(short):
        return ""
    listed = ", ".join(f"{frequencies_hz[i]:.6g} Hz ({error_estimate[i]:.1e})" for i in short[:5])
    more = f" and {len(short) - 5} more" if len(short) > 5 else ""
    return (f"mesh refinement stopped at {counted(elements_per_beam, 'element')} per beam (max_elements_per_beam) "
            f"with {counted(len(short), 'frequency', 'frequencies')} above rtol = {rtol:.0e} (estimated relative error, at least the "
            f"elements' dispersion error on that mesh): {listed}{more}")


def _fixed_mesh_note(fe, computed: int, count, error_estimate) -> str:
    """What a fixed mesh leaves unsaid (empty if nothing): fewer modes than the
    ``count`` asked for (the mesh holds no more), and frequencies whose error
    was not estimated (unchecked)."""
    parts = []
    if count is not None and computed < count:
        parts.append(f"the mesh of {counted(fe.elements_per_beam, 'element')} per beam ({fe.n_dof} DOFs) holds only "
                     f"{computed} of the {counted(count, 'mode')} asked for")
    unknown = int(np.count_nonzero(np.isnan(error_estimate)))
    if unknown:
        parts.append(f"the error of {counted(unknown, 'frequency', 'frequencies')} is not estimated "
                     f"(estimate_error=False): {'it is' if unknown == 1 else 'they are'} unchecked")
    return "; ".join(parts)


def _fixed_mesh(model, elements_per_beam, count, lam_max, estimate_error):
    """One mesh of n elements per beam; each λ's error estimated from its change
    against another mesh, taken as if second order: against half the mesh
    (``|λ_n − λ_n/2| / 3``) where that mesh exists and holds the mode, else
    against twice the mesh (``4 |λ_n − λ_2n| / 3``, a mesh of one element per
    beam, or a mode above those half the mesh holds). For the h⁴ bending error
    both overestimate, about fivefold and 1.25-fold.

    Returns the FEModel, λ, mode vectors and relative error estimates of λ
    (NaN where ``estimate_error`` is False).
    """
    fe = assemble(model, elements_per_beam)
    lam, X, solver = fe_modes(fe, count, lam_max)
    lam_error = np.full(len(lam), np.nan)
    if estimate_error:
        held = 0
        if fe.elements_per_beam >= 2:
            coarse = _lowest(model, fe.elements_per_beam // 2, count, lam_max, len(lam))
            held = len(coarse)
            lam_error[:held] = np.abs(coarse - lam[:held]) / (3 * lam[:held])
        if held < len(lam):
            fine = _lowest(model, 2 * fe.elements_per_beam, count, lam_max, len(lam))
            lam_error[held:] = 4 * np.abs(fine[held:len(lam)] - lam[held:]) / (3 * lam[held:])
    return fe, lam, X, np.maximum(lam_error, solver)


def _lowest(model, elements_per_beam, count, lam_max, at_least):
    """(m,) the lowest λ on a mesh of ``elements_per_beam``, at most ``at_least`` of them."""
    return fe_modes(assemble(model, elements_per_beam), count, lam_max, at_least=at_least)[0][:at_least]


def _refine(model, count, lam_max, rtol, max_elements_per_beam):
    """Mesh doubling with Richardson extrapolation; see :func:`fe_frequencies`.

    Returns the finest FEModel, extrapolated λ, its mode vectors and the
    relative error estimates of λ.
    """
    level_lam_max = None if lam_max is None else 1.5 * lam_max
    levels, n = [], 4
    while True:
        fe = assemble(model, n)
        lam, X, solver = fe_modes(fe, count, level_lam_max,
                                  at_least=len(levels[-1]) if levels else 0)
        levels.append(lam)
        extrapolated, error = _extrapolate(levels)
        error = np.maximum(error, solver)
        reported = np.ones(len(lam), bool) if lam_max is None else extrapolated <= lam_max
        if count is not None:
            reported[count:] = False
        converged = len(levels) >= 3 and np.all(error[reported] / 2 <= rtol)
        if converged or 2 * n > max_elements_per_beam:
            return fe, extrapolated, X, error
        n *= 2
