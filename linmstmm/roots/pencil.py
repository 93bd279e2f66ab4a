"""Refinement by the pencil: Newton on the local linearisation of Ū(ω) (the
generalized eigenvalues μ of (Ū, dŪ/dω) are the offsets to the nearby roots),
all starts at once, with the rounding floor of each root kept as its uncertainty."""

from __future__ import annotations

import numpy as np
import scipy.linalg

from linmstmm.nullspace import equilibration


def pencil(finder, omegas, step: float = 1e-7):
    """(Ū(ω), dŪ/dω), the derivative a forward difference of ``matrix``."""
    steps = step * omegas
    stack = finder.matrix(np.concatenate([omegas, omegas + steps]))
    return stack[:omegas.size], (stack[omegas.size:] - stack[:omegas.size]) / steps[:, None, None]


def offsets(finder, omegas, full=True) -> list[np.ndarray]:
    """For each ω: generalized eigenvalues μ of (Ū(ω), dŪ/dω), sorted by |μ| (complex).

    full : (n,) bool or bool; where False, only the smallest μ is wanted
    (a Newton step short of convergence): it comes from a few power
    iterations on Ū⁻¹ dŪ/dω, and the full eigenvalues only where those do
    not settle (a complex or nearly tied dominant pair).

    One evaluation of Ū for all ω and their neighbours ω(1 + 1e-7) (the
    derivative is a forward difference: its 1e-7 relative error only slows
    Newton's last step by that factor, for a third fewer evaluations than
    a central one); empty where Ū is not finite. μ = 1/ν with ν the
    eigenvalues of Ū⁻¹ dŪ/dω, all ω in one batched solve and eig (dŪ/dω
    is singular: Ū has rows that do not depend on ω; the small μ that
    Newton needs are the large, well-resolved ν). QZ on the pencil is
    the fallback where Ū is exactly singular.
    """
    omegas = np.asarray(omegas, dtype=float)
    n = omegas.size
    A, derivative = finder._pencil(omegas)
    usable = (omegas > 0) & np.isfinite(A).all(axis=(1, 2)) & np.isfinite(derivative).all(axis=(1, 2))
    rows, cols = equilibration(A[usable])
    A = rows[..., :, None] * A[usable] * cols[..., None, :]
    derivative = rows[..., :, None] * derivative[usable] * cols[..., None, :]
    try:
        pencil = inverse_eigenvalues(np.linalg.solve(A, derivative), np.broadcast_to(full, n)[usable])
    except np.linalg.LinAlgError:
        pencil = [scipy.linalg.eigvals(a, d) for a, d in zip(A, derivative)]
    offsets, usable_offsets = [], iter(pencil)
    for ok in usable:
        mu = next(usable_offsets) if ok else np.zeros(0)
        mu = mu[np.isfinite(mu)]
        offsets.append(mu[np.argsort(np.abs(mu))])
    return offsets


def polish(finder, starts, iterations: int = 40, early: bool = False):
    """Converge on the root nearest each start, all starts at once.

    Newton for the nonlinear eigenproblem: ω ← ω − μ with μ the offset
    of smallest size. Stops at |μ| <= xtol·ω, or when the steps stop
    shrinking below UNCERTAIN·ω (the rounding floor of Ū_all); gives up
    on a start whose step twice fails to shrink above that, or is twice
    mostly imaginary and above SPLIT·ω (not near a real root), or once
    reaches beyond NEWTON_REACH·ω.
    ``early``: also stop a round sooner where convergence to a simple root
    is quadratic (:meth:`_quadratic`), for a caller that counts all its
    roots at the end (a double root whose second offset shows only within
    1e-12 of it looks simple a round early).
    Returns a list of (root or None if it did not converge, offsets).
    """
    last_steps = finder.LAST_STEPS_EARLY if early else finder.LAST_STEPS
    omega = np.array(starts, dtype=float)
    previous = np.full(omega.size, np.inf)
    setbacks = np.zeros(omega.size, dtype=int)
    results: list = [(None, np.zeros(0))] * omega.size
    active = list(range(omega.size))
    for _ in range(iterations):
        if not active:
            break
        still = []
        # all offsets only where this step is likely the last (the result keeps them)
        full = previous[active] <= last_steps * omega[active]
        for i, mu, complete in zip(active, finder._offsets(omega[active], full), full):
            if mu.size == 0:
                continue
            step = abs(mu[0])
            if step > finder.NEWTON_REACH * omega[i]:  # lost: not evaluated where it lands
                continue
            omega[i] -= mu[0].real
            settled = step > previous[i] / 2  # no longer shrinking: the rounding floor
            converged = (step <= finder.xtol * omega[i] or (settled and step <= finder.UNCERTAIN * omega[i])
                         or (early and complete and finder._quadratic(step, previous[i], omega[i], mu)))
            if converged and not complete and mu.size == 1:  # its offsets are wanted too
                previous[i] = step
                still.append(i)
            elif converged:
                finder.last_step[omega[i]] = step / omega[i]
                results[i] = (omega[i], mu - mu[0].real)  # offsets seen from the new ω
                finder.offsets_at[omega[i]] = results[i][1]
            else:
                # A mostly imaginary nearest offset sees no real root at its distance:
                # ω creeps by its real part (MLRS above 170 Hz: 40 rounds, 1e-8 each).
                sideways = abs(mu[0].imag) > abs(mu[0].real) and step > finder.SPLIT * omega[i]
                setbacks[i] += (step >= previous[i]) + sideways
                previous[i] = step
                if setbacks[i] < 2:  # Newton that twice fails to shrink its step is lost
                    still.append(i)
        active = still
    return finder._checked(results)


def checked(finder, results):
    """``polish`` results less the roots accepted at the rounding floor (a last step
    above the finder's rtol) that det itself does not bear out: no sign change and no
    dip of log|det| between ω(1 ± 10·step). Where the pencil of Ū_all is not smooth,
    Newton can settle beside a root (random loops 122: 975.90 and 977.07 Hz for one
    root at 976.97, and the count bisection then gave up)."""
    doubtful = [i for i, (root, _) in enumerate(results)
                if root is not None and finder.last_step.get(root, 0.0) > finder.rtol]
    if not doubtful:
        return results
    roots = np.array([results[i][0] for i in doubtful])
    offsets = 10 * np.array([finder.last_step[root] for root in roots])
    sign, log_abs = finder.log_det(np.concatenate([roots * (1 - offsets), roots, roots * (1 + offsets)]))
    sign, log_abs = np.real(sign).reshape(3, -1), log_abs.reshape(3, -1)
    borne_out = (sign[0] * sign[2] < 0) | (np.minimum(log_abs[0], log_abs[2]) > log_abs[1] + finder.DIP)
    results = list(results)
    for i, ok in zip(doubtful, borne_out):
        if not ok:
            results[i] = (None, np.zeros(0))
    return results


def quadratic(finder, step: float, previous: float, omega: float, mu: np.ndarray) -> bool:
    """Whether Newton, having just taken ``step`` after ``previous``, has converged on
    a simple root without another round.

    The step is below EARLY·ω and within 10× the square of the one before
    (quadratic convergence), and the pencil shows one near-zero offset only
    (a multiple root takes the full route). The error left is then about
    max(1e-7 (the forward difference's relative error), 10·step/ω) × step,
    under 1e-16·ω; one more round (a fifth of an MLRS solve) would only
    confirm it.
    """
    return (step <= finder.EARLY * omega and step * omega <= 10 * previous ** 2
            and int(np.sum(np.abs(mu) < finder.SPLIT * omega)) == 1)


def inverse_eigenvalues(stack, full, iterations: int = 6) -> list[np.ndarray]:
    """μ = 1/ν for the eigenvalues ν of each (N, N) matrix of ``stack``: all of them
    where ``full``, else only the dominant ν by power iteration (one-element
    array), falling back to all where it has not settled to 1e-6."""
    n = len(stack)
    vector = np.ones((n, stack.shape[1], 1))
    with np.errstate(invalid="ignore", divide="ignore"):  # a zero vector: NaN, not settled below
        for _ in range(iterations):
            vector = stack @ vector
            vector /= np.linalg.norm(vector, axis=1, keepdims=True)
    image = stack @ vector
    nu = (vector.conj().transpose(0, 2, 1) @ image)[:, 0, 0]
    settled = np.linalg.norm(image[:, :, 0] - nu[:, None] * vector[:, :, 0], axis=1) <= 1e-6 * np.abs(nu)
    out = [np.array([1 / nu[i]]) if (settled[i] and not full[i] and nu[i] != 0) else None for i in range(n)]
    rest = [i for i in range(n) if out[i] is None]
    if rest:
        with np.errstate(divide="ignore"):
            for i, values in zip(rest, np.linalg.eigvals(stack[rest])):
                out[i] = 1 / values[values != 0]
    return out
