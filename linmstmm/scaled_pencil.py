"""The coarse finite-element model the predictions solve, assembled and scaled (:class:`CoarsePencil`).

Its dense K and M are scaled to unit mass per unknown (:func:`_unit_scaled`), so
that the pencil no longer depends on the units the model is written in, and kept
in standard form C = L⁻¹ K L⁻ᵀ once per pencil; :mod:`linmstmm.coarse_prediction`
keeps a pencil per model and mesh and finds the lowest eigenvalues of C.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from linmstmm.fe.node_constraints import kept_node_constraints
from linmstmm.fe.sparse import scipy_csr
from linmstmm.model import Model


@dataclass(frozen=True, eq=False)
class CoarsePencil:
    """The coarse FE model of :func:`~linmstmm.coarse_prediction.coarse_predictions`, assembled and scaled.

    Attributes
    ----------
    assembly : linmstmm.fe.assembly.Assembly
        The assembled model (its K and M dense where small, else sparse).
    rigid_body_modes : int
        Its rigid-body modes, counted as the FE route counts them
        (:func:`linmstmm.fe.rigid_motions.rigid_mode_count`), not formed.
    scale : numpy.ndarray, shape (n,)
        The scaling of each unknown: to unit mass (or stiffness, where it has
        none), the same eigenvalues, and a pencil that no longer depends on
        the units (in km the translations' and rotations' entries lie 1e6
        further apart, and the predictions were 1e-4 to 3e-2 off where in m
        they were 1e-7 to 1e-4 off).
    compiled : bool
        Whether the dense K and M are scaled by the compiled kernel (the same numbers).
    K, M : numpy.ndarray, shape (n, n)
        Dense and scaled, made on first use: the sparse route of a refined mesh
        never asks for them (on the second launcher's 1,284 unknowns they cost
        about 10 ms).
    """

    assembly: object
    rigid_body_modes: int
    scale: np.ndarray
    compiled: bool

    @property
    def size(self) -> int:
        """n, the unknowns of the pencil."""
        return self.scale.size

    @property
    def K(self) -> np.ndarray:
        """(n, n) the scaled stiffness, dense (made on first use)."""
        return self._dense[0]

    @property
    def M(self) -> np.ndarray:
        """(n, n) the scaled mass, dense (made on first use)."""
        return self._dense[1]

    @functools.cached_property
    def _dense(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, M) dense, scaled (:attr:`scale`), read-only: shared by every prediction of this model."""
        K, M = (matrix if isinstance(matrix, np.ndarray) else matrix.toarray()
                for matrix in (self.assembly.K, self.assembly.M))
        if self.compiled:  # the same numbers in one pass
            from linmstmm._product_kernels import unit_scaled

            _, K, M = unit_scaled(K, M)
        else:
            _, K, M = _unit_scaled(K, M)
        for matrix in (K, M):
            matrix.setflags(write=False)
        return K, M

    @property
    def reduced(self) -> np.ndarray | None:
        """The pencil in standard form, C = L⁻¹ K L⁻ᵀ with M = L Lᵀ (lower triangle),
        shape (n, n); None where M is not positive definite (massless unknowns).

        LAPACK's potrf and sygst, the first two steps of the generalized eigensolver
        sygvx, made once per pencil: each prediction then runs only a standard
        eigensolver on C (:func:`linmstmm.coarse_prediction._lowest_eigenvalues`). Up to
        :data:`~linmstmm.standard_eigen.BISECTED` eigenvalues it is syevx (in its
        steps), whose eigenvalues are sygvx's on (K, M) to the bit
        (tests/test_coarse_prediction.py); beyond, syev finds them all at once, not
        to the bit of sygvx's (1e-10 apart on the launcher). A repeat solve of the
        second launcher's ten lowest saved a quarter of its prediction (one asking
        the same count now takes the kept predictions,
        :func:`~linmstmm.coarse_prediction.predict_frequencies`).
        """
        return self._standard[1]

    @functools.cached_property
    def rounding_level(self) -> float:
        """(rad/s)², ε ‖C‖₁ of :attr:`reduced` C (lower triangle held, symmetric): the error
        bound of an eigenvalue of C as LAPACK finds it, so one this close to zero is its
        largest's rounding, its sign arbitrary, by LAPACK's bisection as by the compiled
        one (a varied model's coarse form, ‖C‖ 1.8e21: 27 such values, -1.5e5 to -284 by
        eigvalsh, +8.3e3 by the brackets, where its lowest root is 0.16 (rad/s)²). Four
        times it also took genuine values on the 640 varied solves' forms (a value 123.4
        where the root is 112.5, against 195): 70 solves lost one, 43 so. nan where there
        is no standard form."""
        if self.reduced is None:
            return float("nan")
        lower = np.abs(np.tril(self.reduced))
        sums = lower.sum(axis=0) + lower.sum(axis=1) - np.diag(lower)
        return np.finfo(float).eps * float(np.max(sums, initial=0.0))

    @functools.cached_property
    def _standard(self) -> tuple[np.ndarray, np.ndarray] | tuple[None, None]:
        """(L, C): the Cholesky factor of M (lower) and :attr:`reduced`; (None, None)
        where M is not positive definite."""
        factor, info = scipy.linalg.lapack.dpotrf(self.M, lower=1, clean=0)
        if info:
            return None, None
        reduced, info = scipy.linalg.lapack.dsygst(self.K, factor, itype=1, lower=1)
        for matrix in (factor, reduced):
            matrix.setflags(write=False)  # shared by every prediction of this model
        return factor, reduced

    def at_nodes(self, vectors: np.ndarray, reduced: bool = True) -> np.ndarray:
        """(m, 6 · (points + bodies)): the eigenvectors ``vectors`` (n, m) of
        :attr:`reduced` (y; x = L⁻ᵀ y on the scaled pencil), or of the scaled pencil
        itself (x) where ``reduced`` is False, as displacements and rotations at the
        model's points and mass centres
        (:class:`~linmstmm.coarse_prediction.PredictedModes`): x times
        :attr:`scale` on the assembly's unknowns, and the rows of T at those nodes."""
        if reduced:
            vectors, info = scipy.linalg.lapack.dtrtrs(self._standard[0], vectors, lower=1, trans=1)
        return (self._node_rows @ (self.scale[:, None] * vectors)).T

    @functools.cached_property
    def _node_rows(self):
        """The rows of the assembly's T (scipy CSR) at the full DOFs of the points and
        mass centres, which every mesh numbers first (:mod:`linmstmm.fe.layout`)."""
        model = self.assembly.model
        return scipy_csr(self.assembly.parts.T)[:6 * (len(model.points) + len(model.rigids))]


def assembled_pencil(model: Model, elements_per_beam: int) -> CoarsePencil:
    """The :class:`CoarsePencil` of ``model`` meshed with ``elements_per_beam`` (>= 1),
    made anew (:func:`linmstmm.coarse_prediction.coarse_pencil` keeps it per model): its
    nodes' constraints eliminated once for this and the Wittrick–Williams counter's mesh
    (:func:`~linmstmm.fe.node_constraints.kept_node_constraints`), its rigid-body modes
    counted, not formed; K and M formed by the compiled kernels where numba is loaded
    already (the same numbers)."""
    from linmstmm.determinant import kernels_loaded
    from linmstmm.fe.assembly import assembled
    from linmstmm.fe.rigid_motions import rigid_mode_count

    forms = None
    if kernels_loaded():
        from linmstmm._product_kernels import pencil_forms as forms
    fe = assembled(model, elements_per_beam, kept_node_constraints, forms)
    rigid = rigid_mode_count(fe.model, fe.parts.layout, fe.parts.masters, fe.M)
    return CoarsePencil(fe, rigid, _unit_scale(fe.K.diagonal(), fe.M.diagonal()), forms is not None)


def _unit_scaled(K: np.ndarray, M: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(scale (n,), K (n, n), M (n, n)) of the pencil (K, M) scaled to unit mass per
    unknown, or unit stiffness where it has none (:class:`CoarsePencil`): scale_i is
    1 / √M_ii, or 1 / √|K_ii| where M_ii is not positive, or 1 where both are 0, and
    each entry is multiplied by scale_i scale_j."""
    scale = _unit_scale(np.diag(K), np.diag(M))
    both = np.outer(scale, scale)
    return scale, K * both, M * both


def _unit_scale(stiffness: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """(n,) 1 / √M_ii, or 1 / √|K_ii| where M_ii is not positive, or 1 where both are 0,
    from the diagonals ``stiffness`` K_ii and ``mass`` M_ii (n,) (:func:`_unit_scaled`)."""
    size = np.where(mass > 0, mass, np.abs(stiffness))
    return 1 / np.sqrt(np.where(size > 0, size, 1.0))
