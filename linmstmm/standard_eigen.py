"""The lowest eigenvalues of a dense symmetric standard form, their vectors on demand.

The coarse predictions (:mod:`linmstmm.coarse_prediction`) solve C y = λ y for
the standard form C of their FE pencil. Up to BISECTED eigenvalues wanted this is
LAPACK's syevx in its steps — the reduction to a tridiagonal T = Qᵀ C Q (sytrd),
bisection on T for the eigenvalues (stebz), inverse iteration on T for their
vectors (stein) and the back-transform by Q (ormtr) — each called as syevx calls
it, with its workspace, so the eigenvalues and vectors are syevx's to the bit
(scipy.linalg.eigh(driver="evx")'s; tests/test_coarse_prediction.py). Kept apart,
the steps let a search take the eigenvalues first and the vectors only where it
needs them (:class:`Bisection`): on the launcher's 84 unknowns, its twelve
lowest cost 0.26 ms and their vectors 0.08 ms more, without the reduction and
bisection made again. A search that needs the eigenvalues only to an accuracy (a
fraction of its rtol) has them bracketed to that by compiled Sturm counts
(:mod:`linmstmm._tridiagonal_kernels`, 0.05 ms of the 0.18 ms bisection to rounding),
syevx's bisection made only if the vectors are asked for. Beyond BISECTED all the eigenvalues at once cost less:
syev without the vectors, syevd (divide and conquer) with them.
"""
from __future__ import annotations

import functools

import numpy as np
import scipy.linalg

#: Eigenvalues wanted of a dense standard form up to which only they are found, by
#: bisection (syevx); beyond, all of them at once (syev, or syevd with vectors) costs less: the
#: launcher's 68 lowest of 84 unknowns 1.2 against 0.2 ms, of 180 2.4 against 0.8 ms
#: (at 12 of 84, 0.29 against 0.17 ms, but the few a solve of ten modes predicts stay
#: to the bit those of the generalized solver sygvx).
BISECTED = 40


class Bisection:
    """The ``count`` lowest eigenvalues of a symmetric matrix C (n, n) as syevx finds them,
    and their vectors on demand, made once.

    Parameters
    ----------
    reduced : numpy.ndarray, shape (n, n)
        C, its lower triangle read; not written.
    count : int
        1 <= count < n (all n: syevx takes QR's route, :func:`lowest_eigenpairs`).
    accuracy : float or None
        None: the eigenvalues are syevx's, to rounding. Else the relative accuracy
        they are wanted to, > 0: they are bracketed to it, in compiled code
        (:func:`linmstmm._tridiagonal_kernels.lowest_values`; the launcher's 13
        lowest to 1e-7 in 0.05 ms, against 0.18 ms by stebz), and stebz finds
        them to rounding only if their vectors are asked for (:meth:`vectors`).

    Attributes
    ----------
    values : numpy.ndarray, shape (m,)
        Ascending, m <= count (as many as bisection finds; count with ``accuracy``).
    """

    def __init__(self, reduced: np.ndarray, count: int, accuracy: float | None = None):
        n = reduced.shape[0]
        self._n = n
        self._work = _workspace("dsyevx", n)  # sytrd takes what follows T's three vectors, ormtr what follows tau
        self._reflectors, self._diagonal, self._off_diagonal, self._tau, info = scipy.linalg.lapack.dsytrd(
            reduced, lower=1, lwork=self._work - 3 * n)
        _check(info, "sytrd")
        self._blocked = None
        self._count = count
        if accuracy is None:
            self.values = self._bisected()
        else:
            from linmstmm._tridiagonal_kernels import lowest_values  # numba loads here

            self.values = np.empty(count)
            lowest_values(self._diagonal, self._off_diagonal, count, 2.0 * accuracy, self.values)
        self._vectors = None

    def _bisected(self) -> np.ndarray:
        """(m,) stebz's eigenvalues, ascending, m <= count: bisection on T with syevx's
        arguments (absolute tolerance 0, ordered by T's blocks, then sorted as syevx sorts)."""
        found, values, self._block, self._split, info = scipy.linalg.lapack.dstebz(
            self._diagonal, self._off_diagonal, 2, 0.0, 1.0, 1, self._count, 0.0, "B")[:5]
        _check(info, "stebz")
        self._blocked = values[:found]
        self._order = np.argsort(self._blocked, kind="stable")
        return self._blocked[self._order]

    def vectors(self) -> np.ndarray:
        """(n, m): the eigenvectors of :attr:`values`, in their order, syevx's to the bit
        (of syevx's eigenvalues, which those found to an ``accuracy`` are within it of):
        inverse iteration on T (stein), back-transformed by Q (ormtr: ormqr on T's
        reflectors below its diagonal, row 0 as it is); made once, all of them
        together. (A few alone are not the same: stein takes eigenvalues within 1e-3
        of T's norm for one cluster and orthogonalises each vector against the others
        it makes, which for a stiff pencil's lowest are all of them: without the
        rigid-body modes' vectors, elastic ones came out as rigid-body motions.)"""
        if self._vectors is None:
            if self._blocked is None:  # the values were found to an accuracy only: stebz's, for stein
                self._bisected()
            vectors, info = scipy.linalg.lapack.dstein(self._diagonal, self._off_diagonal, self._blocked,
                                                       self._block, self._split)
            _check(info, "stein")
            vectors = vectors[:, :self._blocked.size]
            if self._n > 1:
                vectors[1:], _, info = scipy.linalg.lapack.dormqr("L", "N", self._reflectors[1:, :-1], self._tau,
                                                                  vectors[1:], lwork=self._work - self._n)
                _check(info, "ormqr")
            self._vectors = vectors[:, self._order]
        return self._vectors


def lowest_eigenpairs(reduced: np.ndarray, count: int, vectors: bool = False, accuracy: float | None = None
                      ) -> tuple[np.ndarray, np.ndarray | None, Bisection | None]:
    """(the ``count`` lowest eigenvalues of the standard form ``reduced`` (n, n) (its lower
    triangle), ascending, or all of them; their eigenvectors (n, m) where ``vectors``,
    else None; the :class:`Bisection` that found them, which gives their vectors later,
    or None): up to BISECTED by syevx's steps (by syevx itself where all n are wanted),
    else all of them at once, by divide and conquer (syevd) with the vectors, by QR
    (syev, dsterf) without. Where bisection finds them without their vectors now, an
    ``accuracy`` (relative) may take them to that only (:class:`Bisection`); every other
    route finds them to rounding.

    LAPACK's routines are called as ``scipy.linalg.eigh(driver="evx" or "ev", lower=True)``
    calls them, with its workspace (:func:`_workspace`), hence its eigenvalues to the bit,
    without its checks and lookups: on the second launcher's 132 unknowns eigh took
    0.59 ms where syevx itself took 0.41 (the ten lowest, best of 200 in one process),
    and a first solve's prediction of either launcher 2 to 8 % less, side by side.
    Beyond BISECTED, syevd's every pair costs less than bisection's few dozen: the
    launcher's 68 lowest of 120 unknowns with their vectors 0.74 ms, against 2.6 ms
    by syevx (0.33 ms without vectors, by syev).
    """
    n = reduced.shape[0]
    if bisects(n, count):
        bisection = Bisection(reduced, count, None if vectors else accuracy)
        return bisection.values, bisection.vectors() if vectors else None, bisection
    if count <= BISECTED:  # all of them: syevx itself, which takes QR's route (sterf, or steqr with vectors) then
        eigenvalues, found_vectors, found, _, info = scipy.linalg.lapack.dsyevx(
            reduced, compute_v=int(vectors), range="I", il=1, iu=count, lower=1, lwork=_workspace("dsyevx", n))
        _check(info, "syevx")
        return eigenvalues[:found], found_vectors[:, :found] if vectors else None, None
    if vectors:
        eigenvalues, found_vectors, info = scipy.linalg.lapack.dsyevd(reduced, compute_v=1, lower=1)
        _check(info, "syevd")
        return eigenvalues, found_vectors, None
    eigenvalues, _, info = scipy.linalg.lapack.dsyev(reduced, compute_v=0, lower=1, lwork=_workspace("dsyev", n))
    _check(info, "syev")
    return eigenvalues, None, None


def bisects(n: int, count: int) -> bool:
    """Whether :func:`lowest_eigenpairs` finds the ``count`` lowest of an order ``n`` form by
    bisection (:class:`Bisection`, whose vectors can come later): up to BISECTED, not all."""
    return count <= BISECTED and count < n


def _check(info: int, routine: str) -> None:
    """Raise where LAPACK's ``routine`` reports failure (``info`` nonzero)."""
    if info:
        raise np.linalg.LinAlgError(f"LAPACK's {routine} failed on the coarse pencil's standard form (info {info})")


@functools.lru_cache(maxsize=None)
def _workspace(routine: str, n: int) -> int:
    """The workspace (doubles) LAPACK's ``routine`` ("dsyev" or "dsyevx") asks for at order
    ``n``, lower triangle: the one scipy.linalg.eigh gives it (its blocking, hence its
    rounding, depends on it)."""
    work, info = getattr(scipy.linalg.lapack, routine + "_lwork")(n, lower=1)
    return int(work)
