"""Predicted natural frequencies: a coarse finite-element model of the same file.

The first step of :mod:`linmstmm.predicted` (predict, polish, certify): the
natural frequencies of a coarse mesh of the model, a dense eigenproblem of a
few hundred unknowns, or a sparse one by block shift-invert Lanczos above
DENSE_PREDICTION (alone above MAX_UNKNOWNS, up to MAX_SPARSE_UNKNOWNS), accurate to
about 1e-3 for the lowest and 1e-2 by the hundredth. The mesh's assembled, scaled pencil depends
on the model alone, so it is kept per model object (:func:`coarse_pencil`).
Completeness is never taken from these predictions: the root search certifies
it by counts.
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from linmstmm.block_lanczos import lowest_eigenvalues, lowest_modes
from linmstmm.elements.beam import bending_wavenumber
from linmstmm.fe.sparse import scipy_csr
from linmstmm.fe.node_constraints import kept_node_constraints
from linmstmm.model import Model
from linmstmm.scaled_pencil import CoarsePencil, assembled_pencil
from linmstmm.standard_eigen import BISECTED, Bisection, bisects, lowest_eigenpairs

#: Radians of a bending wave per element of the predicting mesh: its frequencies are
#: then high by about 1/720 relative, well inside the secant's reach.
WAVE_PER_ELEMENT = 1.0
#: Unknowns of the predicting FE model beyond which the dense eigensolvers do not predict
#: (only the sparse route does, else the scan-based search runs): a dense eigenproblem
#: grows as their cube, and a chain of 1000 bodies took 3.5 s to predict what the search
#: finds in 0.1 s.
MAX_UNKNOWNS = 1500
#: Unknowns beyond MAX_UNKNOWNS up to which the sparse route alone predicts (block
#: shift-invert Lanczos, one element per beam: :func:`_predicted_modes`): a cantilever of
#: 300 beams (1,806 unknowns) its 25 lowest in 27 ms, from which its 20 lowest took 130
#: evaluations of det Ū_all, where the scan took 597; of 3,000 beams (18,006) 0.74 s
#: in all, against 2.5 s.
MAX_SPARSE_UNKNOWNS = 20000
#: A direction of the coarse (K, M) whose images are both below this fraction of
#: their largest entries moves neither stiffness nor mass (:func:`_regular_pencil`).
SINGULAR_PENCIL = 1e-12
#: Unknowns of the predicting FE model above which its eigenproblem is solved sparse
#: (see :func:`coarse_predictions`).
DENSE_PREDICTION = 400
#: A free model's probe shifts for the sparse route, relative to its median stiffness-to-mass
#: diagonal ratio, tried in turn (:func:`_free_shift`), and how far above the rigid-body modes'
#: computed values its lowest elastic eigenvalue must lie to be taken for one.
FREE_PROBE_SHIFTS = (1e-10, 1e-13)
ELASTIC_ABOVE = 100.0
#: Coarse pencils kept (:func:`coarse_pencil`; a model's meshes, least recently used dropped first).
PENCILS_KEPT = 16
#: Elements per beam the predicting mesh may take.
MAX_ELEMENTS = 64


def coarse_predictions(model: Model, count: int, elements_per_beam: int = 2,
                       shift: float | None = None) -> np.ndarray:
    """The lowest ``count`` elastic natural frequencies, rad/s, of a coarse FE model.

    elements_per_beam : Hermite elements per beam; bending frequencies come
    out high by about (βh)⁴/720 relative, h the element length. The dense
    generalized eigenproblem (K, M) in its kept standard form: its lowest
    eigenvalues only, or all at once where more than
    :data:`~linmstmm.standard_eigen.BISECTED` are wanted; where M is singular
    (massless unknowns) by QZ, whose infinite eigenvalues are dropped.
    shift : (rad/s)², below the lowest elastic eigenvalue (half a coarser mesh's
    lowest), given for a refined mesh: where every unknown carries mass and there
    are more than DENSE_PREDICTION of them, sparse block shift-invert Lanczos about
    −shift (:mod:`linmstmm.block_lanczos`, to the prediction's accuracy: on the
    second launcher's 1284 unknowns its 112 lowest in 19 ms, against 54 ms by
    ARPACK to machine precision and far more dense, whose Cholesky route's lowest
    eigenvalue was 2.8e-3 off there); without a shift where the mesh has more than
    DENSE_PREDICTION unknowns, about 0 where it has no rigid-body mode (a cantilever of
    100 beams, 1,200 unknowns: its 25 lowest in 12 ms, 8e-9 from the closed form, against
    0.42 s dense, 2.3e-5 off), else about half its lowest elastic eigenvalue (:func:`_free_shift`).
    The lowest as many as the FE model has rigid-body modes are theirs, and dropped
    (a threshold relative to the largest would drop a soft strip's first bending
    modes with them).
    Returns (m,) ascending, m <= count (fewer if the model has fewer); for a mesh
    of more than MAX_UNKNOWNS unknowns, only what the sparse route gives (up to
    MAX_SPARSE_UNKNOWNS; none where it cannot take the mesh: massless unknowns, or rigid-body
    modes whose shift :func:`_free_shift` cannot find).
    """
    return coarse_modes(model, count, elements_per_beam, shift, nodal=False).values


@dataclass(frozen=True, eq=False)
class PredictedModes:
    """The coarse FE model's lowest elastic modes (:func:`coarse_modes`).

    Attributes
    ----------
    values : numpy.ndarray, shape (m,)
        Natural frequencies, rad/s, ascending.
    nodal : numpy.ndarray, shape (m, 6 · (points + bodies)), or None
        Each mode's displacements (m) and rotations (rad) at the model's points and
        rigid bodies' mass centres, six per node in the inertial frame, in the order
        of the full DOFs of :mod:`linmstmm.fe.layout` (the nodes every mesh numbers
        first): the eigenvector there, unnormalised (a Ritz vector on the sparse
        route). None where they were not asked for, or the pencil has massless
        unknowns (QZ gives no vectors).
    later : callable (rows=None) -> numpy.ndarray, or None
        Where ``nodal`` is None and the eigensolve can give the modes afterwards
        (bisection, :class:`~linmstmm.standard_eigen.Bisection`): what ``nodal`` would
        have been, the same to the bit, without the eigenvalues found again; given
        ``rows`` (k indices into ``values``), those rows of it.
    """

    values: np.ndarray
    nodal: np.ndarray | None
    later: Callable[..., np.ndarray] | None = field(default=None, repr=False)


def coarse_modes(model: Model, count: int, elements_per_beam: int = 2, shift: float | None = None,
                 nodal: bool = True, later: bool = False, accuracy: float | None = None) -> PredictedModes:
    """:func:`coarse_predictions` with the modes at the nodes (``nodal``): the
    :class:`PredictedModes` of the mesh of ``elements_per_beam``; with ``later``, the
    modes are left to :attr:`PredictedModes.later` where the eigensolve can make them
    afterwards (bisection), else made now. Where they are left so, an ``accuracy``
    (relative) takes the frequencies to that only, by a compiled kernel
    (:class:`~linmstmm.standard_eigen.Bisection`; numba loads there); else they are
    found to rounding.

    The vectors come from the same eigensolve as the frequencies (:func:`_lowest_eigenvalues`).
    Up to :data:`~linmstmm.standard_eigen.BISECTED` that is syevx's steps, which give
    the same frequencies with them, bit for bit, about 80 µs more on the launcher's 84
    unknowns for its 12 lowest, now or later (:attr:`PredictedModes.later`); beyond,
    syevd with them and syev without, whose frequencies agree to rounding only; on the
    sparse route the Lanczos's Ritz vectors, with the same frequencies. An eigenvalue of
    the dense standard form within its rounding level of zero
    (:attr:`~linmstmm.scaled_pencil.CoarsePencil.rounding_level`) is zero, whatever sign
    the eigensolver gave it: no prediction (:func:`linmstmm.roots.floor.usable`).
    """
    dense = elements_per_beam <= _finest_mesh(model)  # else a dense solve costs more than the search saves
    if not dense and (_unknowns(model, elements_per_beam) > MAX_SPARSE_UNKNOWNS or not _points_carry_mass(model)):
        return PredictedModes(np.zeros(0), None)  # (the sparse route's pencil unassembled)
    pencil = coarse_pencil(model, elements_per_beam)
    if pencil.size == 0:  # every point held: no unknown, no mode (LAPACK takes no empty matrix)
        return PredictedModes(np.zeros(0), None)
    rigid = pencil.rigid_body_modes
    if shift is None and pencil.size > DENSE_PREDICTION:  # the sparse route, where it can turn about a shift
        shift = 0.0 if rigid == 0 else _free_shift(pencil)  # (rigid == 0: K positive definite)
    if not dense and not _sparse_route(pencil, shift):
        return PredictedModes(np.zeros(0), None)
    wanted = min(count + rigid, pencil.size)
    now = nodal and not (later and _bisected(pencil, wanted, shift))
    loose = accuracy is not None and later and not now  # (λ = ω²: twice ω's accuracy)
    lam, vectors, reduced, bisection = _lowest_eigenvalues(pencil, wanted, shift, now,
                                                           2.0 * accuracy if loose else None, dense)
    if lam is None:
        return PredictedModes(np.zeros(0), None)
    if reduced and pencil.reduced is not None:  # (else QZ, or the sparse route's Ritz values)
        lam = np.where(np.abs(lam) <= pencil.rounding_level, 0.0, lam)  # rounding, whatever its sign
    order = np.argsort(lam)[rigid:rigid + count]
    values = np.sqrt(np.maximum(lam[order], 0.0))
    if vectors is not None:
        return PredictedModes(values, pencil.at_nodes(vectors[:, order], reduced))
    later = None if bisection is None else (
        lambda rows=None: pencil.at_nodes(bisection.vectors()[:, order if rows is None else order[rows]], reduced))
    return PredictedModes(values, None, later)


def _free_shift(pencil: CoarsePencil) -> float | None:
    """A shift (rad/s)² for the sparse route on ``pencil``, whose stiffness its rigid-body
    modes make singular: half its lowest elastic eigenvalue, as a refined mesh takes from a
    coarser one, found first by the same route asking for one eigenvalue beyond the
    rigid-body modes, about each of FREE_PROBE_SHIFTS times its median stiffness-to-mass
    diagonal ratio in turn until one gives an answer (a long flexible model's lowest
    elastic eigenvalue lies far below that ratio, as the fourth power of its elements'
    length over its own, and a probe too far above it does not converge); None where none
    does, or none above ELASTIC_ABOVE times the rigid-body modes' computed values (their
    rounding about 0). A free rod of 1,000 beams: those within ±0.84 (rad/s)², its lowest
    elastic 1.67e5 (409.128 rad/s), about the first probe, 1.1e6; of 3,000 beams, the
    second (the first, 1.1e8, gave no answer)."""
    rigid = pencil.rigid_body_modes
    if not _every_unknown_carries_mass(pencil):
        return None
    ratio = float(np.median(pencil.assembly.K.diagonal() / pencil.assembly.M.diagonal()))
    for probe in FREE_PROBE_SHIFTS:
        found = _sparse_lowest(pencil, rigid + 1, probe * ratio, False)
        if found is not None:
            lam = np.sort(found[0])
            return 0.5 * float(lam[rigid]) if lam[rigid] > ELASTIC_ABOVE * np.max(np.abs(lam[:rigid])) else None
    return None


def coarse_pencil(model: Model, elements_per_beam: int) -> CoarsePencil:
    """The :class:`CoarsePencil` of ``model`` meshed with ``elements_per_beam``: assembled
    on the first call for this model object (its nodes' constraints eliminated once
    for this and the Wittrick–Williams counter's mesh,
    :func:`~linmstmm.fe.node_constraints.kept_node_constraints`; its rigid-body
    modes counted, not formed), the same after (a Model cannot change; see
    :mod:`linmstmm.compiled_model`). ``coarse_pencil.cache_clear()`` drops every
    pencil, node elimination and prediction kept.

    Parameters
    ----------
    model : Model
        The model.
    elements_per_beam : int
        Hermite elements per beam, >= 1.

    Returns
    -------
    CoarsePencil
    """
    return _pencil(model, elements_per_beam)


#: :func:`coarse_pencil`'s store: the PENCILS_KEPT last used.
_pencil = functools.lru_cache(maxsize=PENCILS_KEPT)(assembled_pencil)


def _forget_pencils() -> None:
    """Drop every coarse pencil, node elimination and prediction kept (:func:`coarse_pencil`)."""
    _pencil.cache_clear()
    _forget_predictions()
    kept_node_constraints.cache_clear()


coarse_pencil.cache_clear = _forget_pencils


def _unknowns(model: Model, elements_per_beam: int) -> int:
    """Unknowns of ``model``'s FE model of ``elements_per_beam``, before its constraints
    are eliminated: six per point, body and interior beam node."""
    return 6 * (len(model.points) + len(model.rigids) + (elements_per_beam - 1) * len(model.beams))


def _points_carry_mass(model: Model) -> bool:
    """Whether every point of ``model`` is the end of a beam with mass, a rigid body's port
    or held in all six components: else it is likely an unknown without mass (a point
    between two springs), which the sparse route cannot take (:func:`_sparse_route`) and
    whose pencil is then not worth assembling (a chain of 1,000 springs and bodies: 0.13 s)."""
    carried = {point for beam in model.beams if beam.rho * beam.A > 0 for point in beam.ends}
    carried.update(point for body in model.rigids for point in body.ports)
    carried.update(point for point, held in model.boundary.items() if np.all(held))
    return carried.issuperset(model.points)


def _finest_mesh(model: Model) -> int:
    """The most elements per beam whose predicting FE model has at most MAX_UNKNOWNS
    unknowns (6 per point, body and interior beam node); below 1 where even one is too many."""
    nodes = len(model.points) + len(model.rigids)
    if not model.beams:
        return MAX_ELEMENTS if 6 * nodes <= MAX_UNKNOWNS else 0
    return (MAX_UNKNOWNS // 6 - nodes) // len(model.beams) + 1


def _regular_pencil(K: np.ndarray, M: np.ndarray):
    """(K, M) less one unknown per motion with neither stiffness nor mass (a massless
    point free to turn between two joints), which makes the pencil singular and QZ's
    eigenvalues arbitrary. Each such motion v (K v = M v = 0, both scaled to their
    largest entry) is removed exactly by holding the unknown it moves most (pivoted
    QR): every vector is one that holds it plus a multiple of v.
    """
    stacked = np.vstack([K / max(np.abs(K).max(), np.finfo(float).tiny),
                         M / max(np.abs(M).max(), np.finfo(float).tiny)])
    motions = scipy.linalg.null_space(stacked, rcond=SINGULAR_PENCIL)
    if not motions.shape[1]:
        return K, M
    held = scipy.linalg.qr(motions.T, pivoting=True, mode="r")[1][:motions.shape[1]]
    kept = np.setdiff1d(np.arange(K.shape[0]), held)
    return K[np.ix_(kept, kept)], M[np.ix_(kept, kept)]


def _lowest_eigenvalues(pencil: CoarsePencil, count: int, shift: float | None, vectors: bool = False,
                        accuracy: float | None = None,
                        dense: bool = True) -> tuple[np.ndarray | None, np.ndarray | None, bool, Bisection | None]:
    """(at least the ``count`` lowest eigenvalues of ``pencil`` (K, M), (rad/s)², in
    any order; their eigenvectors (n, m) if ``vectors`` asks and the route gives them,
    else None; whether those are of :attr:`CoarsePencil.reduced` (y), not of the scaled
    pencil itself (x); the :class:`~linmstmm.standard_eigen.Bisection` that gives
    those vectors later, in the eigenvalues' order, where the route has one, else None):
    by block shift-invert Lanczos about −shift
    (:mod:`linmstmm.block_lanczos`, x) where a shift is given, every unknown carries
    mass and there are more than DENSE_PREDICTION; else on the kept standard form
    (:func:`~linmstmm.standard_eigen.lowest_eigenpairs`, y); by QZ where M is singular,
    the infinite eigenvalues dropped, without vectors. ``accuracy``: as
    :func:`~linmstmm.standard_eigen.lowest_eigenpairs` takes it, of the eigenvalues.
    Unless ``dense`` allows the dense routes, (None, None, False, None) where the
    sparse one gives no answer."""
    if _sparse_route(pencil, shift):
        found = _sparse_lowest(pencil, count, shift, vectors)
        if found is not None:
            return *found, False, None
    if not dense:
        return None, None, False, None
    if pencil.reduced is None:  # massless unknowns: QZ, their eigenvalues infinite
        K, M = _regular_pencil(pencil.K, pencil.M)
        lam = scipy.linalg.eigvals(K, M)
        return lam[np.isfinite(lam)].real, None, True, None
    lam, found_vectors, bisection = lowest_eigenpairs(pencil.reduced, count, vectors, accuracy)
    return lam, found_vectors, True, bisection


def _bisected(pencil: CoarsePencil, count: int, shift: float | None) -> bool:
    """Whether :func:`_lowest_eigenvalues` finds ``count`` of ``pencil``'s eigenvalues by
    bisection on its standard form, which can give their vectors afterwards."""
    return not _sparse_route(pencil, shift) and pencil.reduced is not None and bisects(pencil.size, count)


def _sparse_route(pencil: CoarsePencil, shift: float | None) -> bool:
    """Whether :func:`_lowest_eigenvalues` tries the sparse route first: a shift given,
    more than DENSE_PREDICTION unknowns, every one carrying mass."""
    return shift is not None and pencil.size > DENSE_PREDICTION and _every_unknown_carries_mass(pencil)


def _every_unknown_carries_mass(pencil: CoarsePencil) -> bool:
    """Whether every unknown of ``pencil`` has mass (M positive on its diagonal), as the sparse
    route's M inner product needs."""
    return bool(np.all(pencil.assembly.M.diagonal() != 0))


def _sparse_lowest(pencil: CoarsePencil, count: int, shift: float,
                   vectors: bool) -> tuple[np.ndarray, np.ndarray | None] | None:
    """(the ``count`` lowest eigenvalues, (rad/s)², of ``pencil``'s sparse assembly scaled
    as its dense K and M are; their Ritz vectors (n, count) of that scaled pencil if
    ``vectors``, else None), by block shift-invert Lanczos about −shift; None where
    that gives no answer."""
    from scipy.sparse import diags  # imported where used: the command line starts without it

    scaling = diags(pencil.scale)
    K, M = (scaling @ scipy_csr(matrix) @ scaling for matrix in (pencil.assembly.K, pencil.assembly.M))
    if vectors:
        return lowest_modes(K, M, count, shift)
    lam = lowest_eigenvalues(K, M, count, shift)
    return None if lam is None else (lam, None)


def predict_frequencies(model: Model, count: int) -> np.ndarray:
    """:func:`coarse_predictions` on a mesh fine enough for the highest of them.

    Two elements per beam first (one beyond MAX_UNKNOWNS: :func:`_predicted_modes`);
    where the beams' bending waves at the highest prediction need more than twice as
    many elements for :data:`WAVE_PER_ELEMENT` radians each, once more with that many: at most MAX_ELEMENTS per beam, and
    at most as many as keep the model within MAX_UNKNOWNS (the finest that does,
    where more would be needed: without predictions the scan-based search took
    24,708 evaluations for the second launcher's 100 lowest on a mesh of 1,800
    unknowns, which a twice finer wave per element asked for).

    The last answer is kept (:func:`_kept_modes`): a parameter study's first
    step asks again, with the count its root search asked for, to measure the
    predictions' error at the roots found (:func:`linmstmm.warm_starts.prediction_error`),
    and a repeat solve of a model asks again; neither solves the eigenproblem anew.
    ``predict_frequencies.cache_clear()`` drops it (the benchmarks time a compiled
    model's solve with its eigensolve made afresh, as the FE eigensolver's is).

    Parameters
    ----------
    model : Model
        The model.
    count : int
        Elastic frequencies wanted, >= 1.

    Returns
    -------
    numpy.ndarray, shape (m,), rad/s
        Ascending, m <= count (:func:`coarse_predictions`); a copy, the caller's own.
    """
    return _kept_modes(model, count, nodal=False).values.copy()


def predicted_modes(model: Model, count: int, later: bool = False, accuracy: float | None = None) -> PredictedModes:
    """:func:`predict_frequencies` with the modes at the model's points and mass
    centres where the eigensolver gives them (:class:`PredictedModes`), kept as the
    frequencies are (the frequencies are the same, to the bit, where the eigensolver
    finds fewer than all of them: :func:`coarse_modes`).

    Parameters
    ----------
    model : Model
        The model.
    count : int
        Elastic frequencies wanted, >= 1.
    later : bool
        Whether the modes may be left to :attr:`PredictedModes.later` where the
        eigensolve can make them afterwards (bisection: the launcher's 12 lowest on
        its 84 unknowns 0.27 ms, their modes 0.08 ms more, only where asked for);
        else they are made now.
    accuracy : float or None
        With ``later``, the relative accuracy the frequencies are wanted to, where less
        than rounding saves time, found by a compiled kernel (:func:`coarse_modes`);
        None: to rounding.

    Returns
    -------
    PredictedModes
        Shared with later calls: not to be written into.
    """
    return _kept_modes(model, count, nodal=True, later=later, accuracy=accuracy)


#: [((model, count, whether the modes at the nodes were asked for, the frequencies' accuracy
#: or None), PredictedModes)]: the last made.
_kept = [(None, None)]


def _kept_modes(model: Model, count: int, nodal: bool, later: bool = False,
                accuracy: float | None = None) -> PredictedModes:
    """The last :class:`PredictedModes` made, where it was made for ``model`` and ``count``,
    its frequencies to rounding or to an ``accuracy`` no coarser than asked, with the modes
    at the nodes if ``nodal`` asks for them (now, or ``later`` where they can come so);
    else made anew and kept."""
    key, kept = _kept[0]  # read once: another thread may replace it
    if key is not None and key[0] is model and key[1] == count and (
            key[3] is None or (accuracy is not None and later and key[3] <= accuracy)):
        if not nodal or kept.nodal is not None:
            return kept
        if kept.later is not None:  # the modes of the frequencies handed out already can come
            if later:
                return kept
            made = PredictedModes(kept.values, kept.later())
            _kept[0] = (model, count, True, key[3]), made
            return made
        if key[2]:  # asked for before, and the eigensolve gives none (QZ)
            return kept
    made = _predicted_modes(model, count, nodal, later, accuracy)
    _kept[0] = (model, count, nodal, accuracy if later else None), made
    return made


def _predicted_modes(model: Model, count: int, nodal: bool, later: bool = False,
                     accuracy: float | None = None) -> PredictedModes:
    """:func:`predicted_modes` made anew (the modes at the nodes only if ``nodal``, now or
    ``later`` where they can come so): two elements per beam, or as many as the highest
    frequency's bending waves need; one per beam where even two are beyond the dense
    route (MAX_UNKNOWNS), by the sparse one alone (:func:`coarse_modes`: a model of
    that many beams has short ones; a chain of 1,000 beams' 25 lowest in 10 ms, against
    21 ms on two). The first mesh's frequencies decide; its
    modes come with them where bisection finds them (up to BISECTED) and they are
    wanted now, else only where no finer mesh follows. (Where every eigenvalue is
    wanted, syevx's frequencies with the vectors and without differ at rounding,
    1e-13 on a varied model's 24 unknowns, and the finer mesh's shift with them.)"""
    first = 2 if _finest_mesh(model) >= 2 else 1  # beyond the dense route's reach the sparse one's, coarsest
    # the modes with the first frequencies where they come with them: bisection's, or the
    # sparse route's Ritz vectors (asked later, a second Lanczos, after the dense standard
    # form that decides it: 0.15 s more on a cantilever of 100 beams' 40 lowest)
    with_first = nodal and not later and (count <= BISECTED or first == 1
                                          or coarse_pencil(model, first).size > DENSE_PREDICTION)
    predicted = coarse_modes(model, count, first, nodal=with_first, later=later, accuracy=accuracy)
    needed = first
    if model.beams and predicted.values.size:
        beta_L = max(bending_wavenumber(beam, predicted.values[-1]) * beam.length for beam in model.beams)
        needed = min(int(np.ceil(beta_L / WAVE_PER_ELEMENT)), MAX_ELEMENTS, max(_finest_mesh(model), first))
    if needed > 2 * first:
        return coarse_modes(model, count, needed, shift=0.5 * predicted.values[0] ** 2, nodal=nodal, later=later,
                            accuracy=accuracy)
    if with_first or not nodal or (later and predicted.later is not None):
        return predicted
    if predicted.later is not None:
        return PredictedModes(predicted.values, predicted.later())
    if predicted.values.size and coarse_pencil(model, 2).reduced is not None:
        return coarse_modes(model, count, 2, nodal=True)
    return predicted


def _forget_predictions() -> None:
    """Drop the kept predictions (:func:`predict_frequencies`)."""
    _kept[0] = (None, None)


predict_frequencies.cache_clear = _forget_predictions
