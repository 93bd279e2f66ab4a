"""Predictions refined by the Rayleigh functional of the exact dynamic stiffness.

The coarse FE model of :mod:`linmstmm.coarse_prediction` predicts each natural
frequency high, by 1e-8 to 1e-3 on the bundled launchers' twenty lowest. Its mode
at the model's points and mass centres — the nodes of the Wittrick–Williams
counter's exact dynamic stiffness D(ω) (:class:`~linmstmm.wittrick_williams.ModeCounter`)
— is far closer to the exact one than the frequency suggests, and D(ω) is
symmetric: the Rayleigh functional p(x), the root ω of xᵀ D(ω) x nearest the
prediction, is stationary at a mode, so its error is quadratic in the vector's.
One step of inverse iteration on D at the prediction first, x ← D(ω)⁻¹ W x
(W the diagonal of the scale of D's terms, so the step does not depend on the
units), shrinks the vector's error by about the prediction's error over the
distance to the next natural frequency; where p then lies more than SETTLED from
where the step was taken, the step is made again at p (Rayleigh quotient
iteration), at most INVERSE_STEPS times. Each evaluation of the functional sums
the beams' exact stiffness over their ends' displacements and the springs' and
bodies' terms of x once formed; the steps factorise D(ω) on the counter's sparse
plan (:mod:`linmstmm._stiffness_kernels`, :func:`~linmstmm._stiffness_kernels.rayleigh_roots`;
this module's functions are the numpy reference, which the numpy engine runs).

On the launchers' 20 lowest the coarse predictions are 1e-8 to 5e-4 off the roots
found, the Rayleigh values of the coarse modes 1e-14 to 8e-6, and after the
inverse steps 1e-16 to 2e-11 (median 4e-14). A refined value is still only a
prediction: det Ū_all is evaluated at the ends of a bracket (BRACKET)
about it, the root is the secant point inside it,
and the roots are certified by counts as any others
(:mod:`linmstmm.predicted`).
"""
from __future__ import annotations

import numpy as np

from linmstmm.prediction_groups import clustered, polished_up_to, standing

#: Relative half-width of the bracket about a refined prediction (:func:`refined_predictions`):
#: det Ū_all is evaluated at its ends, in the secant's first batch, and where det changes
#: sign there the secant point between them is the root, two evaluations in all
#: (:func:`~linmstmm.secant.secant_roots`). A tenth of the default rtol, a thousand times
#: the launchers' roots' rounding floor; given where the rtol is at least ten times it
#: (below, a refined prediction only starts the secant).
BRACKET = 1e-10
#: Relative first step of the secant on the Rayleigh functional (its second point).
FIRST_STEP = -1e-7
#: Secant steps on the functional before it is given up.
FORM_STEPS = 30
#: A secant step on the functional below this (relative) ends it: superlinear, the
#: root is then known far closer than a refined prediction needs (BRACKET).
FORM_XTOL = 1e-13
#: A secant on the functional that rises after a step below this (relative) has met
#: its rounding, and ends there; after a longer step it straddles a pole of D(ω)
#: (near a beam's clamped–clamped frequency the functional's terms grow without bound:
#: a cantilever's root 7e-6 from one was known to 1e-13 only).
FORM_FLOOR = 1e-10
#: The factorisation of D(ω) in an inverse step is refused where an entry of
#: diag(|L| |D| |L|ᵀ) exceeds this many times the largest equilibrated term: its
#: backward error, about 1e-16 times that, stays far below the relative distance to
#: a root at which the step is taken (the count's bound of 100 refused 11 of the
#: launchers' 60 lowest; at 1e4 none).
SOLVE_GROWTH = 1e6
#: A Rayleigh value within this (relative) of where its inverse step was taken is
#: final: the vector then was within about this much over the distance to the next
#: root of the mode, and its Rayleigh value within the square of that.
SETTLED = 1e-5
#: Inverse steps made at most for one prediction.
INVERSE_STEPS = 3
#: From this rtol up, a coarse mode's Rayleigh value is taken without inverse steps
#: (:func:`refined_predictions`): on the launchers' 20 lowest those are within 8.5e-6 of
#: the roots, so each stands as it is where the Wittrick–Williams counts at ±rtol find
#: one natural frequency across it (:mod:`linmstmm.predicted`), and the inverse steps'
#: factorisations of D(ω) are saved (the launcher's ten lowest, predictions kept:
#: 0.67 -> 0.56 ms, a sixth of such a solve). Where one does not
#: stand it is polished by the secant as any prediction.
UNSTEPPED_FROM = 1e-4
#: From this rtol up, where the predictions may stand unpolished, each is first tried
#: as the coarse model gives it, its mode left for later (:func:`refined_predictions`'
#: ``as_predicted``): the FE model is exact for rigid bodies and springs, and where the
#: beams are stiff at the frequencies wanted its values are the roots to a few 1e-6 (the
#: launchers' ten lowest: 2.0e-6 at most), so counts at ±rtol certify them as they are,
#: and neither their eigenvectors, their values at the nodes nor their Rayleigh values
#: are made. One that does not stand costs the two counts across it and is refined as
#: before, its mode made then. At 1e-6 nine of the launcher's ten lowest stand, 15 and
#: 18 of the launchers' 22 that their twenty lowest try, and those solves take 0.75–0.85
#: of the time they took refining all (1e-5: 0.65, as at 1e-4); at 1e-7 two of ten stand.
AS_PREDICTED_FROM = 1e-6
#: The coarse model's frequencies tried as they are are found to this fraction of the rtol
#: asked for (relative), not to rounding (:class:`~linmstmm.standard_eigen.Bisection`'s
#: ``accuracy``), or to the coarse form's own rounding where that is coarser (4 ε ‖T‖ of
#: its eigenvalues: a stiff random tree's moved 1.6e-6 at every rtol): far below the coarse
#: model's own error where it stands, the counts at ±rtol alone certify each, and the
#: launcher's 13 lowest took 0.05 ms to 1e-7, against 0.18 ms to rounding.
PREDICTED_TO = 1e-3
#: Relative step of the central difference D′(ω) x of an inverse step: its truncation
#: error (about its square) and rounding (about 1e-16 over it) both far below what the
#: step needs.
DERIVATIVE_STEP = 1e-6


def refined_predictions(counter, modes, count: int, rtol: float,
                        as_predicted: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(predictions (m,) rad/s, ascending; spans (m,)): the coarse predictions ``modes``
    (:class:`~linmstmm.coarse_prediction.PredictedModes`) of a search for the lowest
    ``count`` to ``rtol``, with those it polishes (:func:`~linmstmm.predicted.polished_up_to`;
    the others only place its last count) that are alone
    (none other within CLUSTER) replaced by their Rayleigh values where the refinement
    settles within half the distance to the nearest other prediction (without inverse
    steps from UNSTEPPED_FROM up); BRACKET in ``spans`` for each of those refined with
    inverse steps where ``rtol`` is at least ten times it, else 0. As they
    are, spans 0, without a ``counter`` (:class:`~linmstmm.wittrick_williams.ModeCounter`)
    or modes at the nodes, or where D(ω) has no unknowns (every node held: J₀ counts all).

    With ``as_predicted`` (AS_PREDICTED_FROM) those alone that the counts at ±rtol
    certify as they are (:func:`~linmstmm.prediction_groups.standing`) stay so, and only
    the others are refined, their modes made then where ``modes`` leaves them for later
    (``modes.later``)."""
    values = np.asarray(modes.values, dtype=float)
    spans = np.zeros(values.size)
    if counter is None or not values.size or not counter.n_dof:
        return values, spans
    polished = polished_up_to(values, count) if count <= values.size else values.size
    tried = np.flatnonzero(~np.array(clustered(values), dtype=bool)[:polished])
    if as_predicted and tried.size:
        tried = tried[~np.array(standing(counter, values.tolist(), tried.tolist(), rtol), dtype=bool)]
    nodal = _modes_of(modes, tried) if tried.size else None
    if nodal is None:
        return values, spans
    stepped = rtol < UNSTEPPED_FROM
    found = counter.rayleigh_values(nodal[:, counter.masters], values[tried],
                                    INVERSE_STEPS if stepped else 0)
    apart = np.abs(np.diff(values))
    nearest = np.minimum(np.r_[np.inf, apart], np.r_[apart, np.inf])
    reach = 0.5 * np.where(np.isfinite(nearest), nearest, values)[tried]
    with np.errstate(invalid="ignore"):
        settled = np.abs(found - values[tried]) <= reach  # False where NaN
    values = values.copy()
    values[tried[settled]] = found[settled]
    if stepped and rtol >= 10 * BRACKET:
        spans[tried[settled]] = BRACKET
    return values, spans


def _modes_of(modes, rows: np.ndarray) -> np.ndarray | None:
    """The modes at the nodes of the predictions ``rows`` of ``modes`` (a
    :class:`~linmstmm.coarse_prediction.PredictedModes`): those it holds, or made now
    where it left them for later; None where it has none."""
    if modes.nodal is not None:
        return modes.nodal[rows]
    return None if modes.later is None else modes.later(rows)


def rayleigh_values_in_numpy(counter, vectors: np.ndarray, starts: np.ndarray,
                             inverse_steps: int = INVERSE_STEPS) -> np.ndarray:
    """The numpy reference of :func:`linmstmm._stiffness_kernels.rayleigh_roots`: for each
    row x of ``vectors`` (m, n_dof), from ω₀ = ``starts`` (m,) rad/s, an inverse step at
    ω_k (:func:`_inverse_steps`) and ω_(k+1) the root of xᵀ D(ω) x nearest ω_k
    (:func:`_form_roots`), until ω_(k+1) lies within SETTLED of ω_k (then ω_(k+1)), at
    most ``inverse_steps`` times (NaN where that is not reached or a step fails); with
    ``inverse_steps`` 0, the root of xᵀ D(ω) x nearest ω₀ for x as given. All rows
    step together; D(ω) dense, by :meth:`~linmstmm.wittrick_williams.ModeCounter.matrices`,
    solved by LU with partial pivoting.

    Parameters
    ----------
    counter : ModeCounter
        The model's counter.
    vectors : (m, n_dof) float
        Displacements (m) and rotations (rad) on the counter's unknowns.
    starts : (m,) float
        rad/s.
    inverse_steps : int
        Inverse steps made at most for one row.

    Returns
    -------
    numpy.ndarray, shape (m,), rad/s
    """
    vectors = np.array(vectors, dtype=float)
    omegas = np.array(starts, dtype=float)
    if inverse_steps == 0:
        return _form_roots(counter, vectors, omegas)
    out = np.full(omegas.size, np.nan)
    active = np.arange(omegas.size)
    for _ in range(inverse_steps):
        if not active.size:
            break
        stepped = _inverse_steps(counter, vectors, omegas, active)
        active = active[stepped]
        new = _form_roots(counter, vectors[active], omegas[active])
        with np.errstate(invalid="ignore"):
            settled = np.abs(new - omegas[active]) <= SETTLED * new
        out[active[settled]] = new[settled]
        going = np.isfinite(new) & ~settled
        omegas[active] = new
        active = active[going]
    return out


def _inverse_steps(counter, vectors: np.ndarray, omegas: np.ndarray, active: np.ndarray) -> np.ndarray:
    """(len(active),) bool: rows ``active`` of ``vectors`` (m, n) each replaced by
    D(ω)⁻¹ D′(ω) x at its ``omegas`` (D′(ω) x by the differences of
    :meth:`~linmstmm.wittrick_williams.ModeCounter.differences`, DERIVATIVE_STEP), the
    solve on D equilibrated by the diagonal of |D|(ω) (as the count equilibrates it),
    scaled to a largest entry of 1; False, the row left, where D(ω) is not finite, a
    DOF has no term, or the solve fails."""
    ok = np.zeros(active.size, dtype=bool)
    if not active.size:
        return ok
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # a clamped pole: the step fails
        matrices, magnitudes = counter.matrices(omegas[active])
        sides = counter.differences(vectors[active], omegas[active], DERIVATIVE_STEP)
    for k, i in enumerate(active):
        matrix, scale = matrices[k], magnitudes[k].diagonal()
        if not (np.all(scale > 0) and np.all(np.isfinite(matrix)) and np.all(np.isfinite(sides[k]))):
            continue
        weights = 1.0 / np.sqrt(scale)
        try:
            z = np.linalg.solve(matrix * weights[:, None] * weights[None, :], weights * sides[k])
        except np.linalg.LinAlgError:
            continue
        y = weights * z
        size = np.max(np.abs(y))
        if size > 0 and np.isfinite(size):
            vectors[i], ok[k] = y / size, True
    return ok


def _form_roots(counter, vectors: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """(m,) rad/s: for each row x of ``vectors`` (m, n) the root of xᵀ D(ω) x
    (:meth:`~linmstmm.wittrick_williams.ModeCounter.forms`) nearest ``starts`` (m,) by the
    secant method from ω₀ and ω₀ (1 + FIRST_STEP), to a step below FORM_XTOL (or a value
    exactly 0, or one that no longer changes, or a rise after a step below FORM_FLOOR);
    NaN where FORM_STEPS steps do not reach it, a value is not finite or the secant rises
    after a longer step (it straddles a beam's clamped–clamped frequency):
    :func:`linmstmm._stiffness_kernels._form_root`."""
    roots = np.full(starts.size, np.nan)
    old, omega = starts.copy(), starts * (1 + FIRST_STEP)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        f_old, f = counter.forms(vectors, old), counter.forms(vectors, omega)
        active = np.arange(starts.size)
        for _ in range(FORM_STEPS):
            finite = np.isfinite(f_old) & np.isfinite(f)
            rising = (f - f_old) * (omega - old) > 0
            # a root, the functional's rounding floor; a rise after a longer step straddles a pole
            ended = finite & ((f == 0.0) | (f == f_old) | (rising & (np.abs(omega - old) <= FORM_FLOOR * omega)))
            finite &= ~rising
            roots[active[ended]] = omega[ended]
            new = omega - f * (omega - old) / (f - f_old)
            moving = finite & ~ended & (new > 0) & np.isfinite(new)
            done = moving & (np.abs(new - omega) <= FORM_XTOL * new)
            roots[active[done]] = new[done]
            going = moving & ~done
            if not going.any():
                break
            active, vectors = active[going], vectors[going]
            old, f_old, omega = omega[going], f[going], new[going]
            f = counter.forms(vectors, omega)
    return roots
