"""A model compiled once for the root search: everything about it that does not
depend on ω, kept for the next solve of the same model object.

Before the first evaluation of det Ū_all a solve builds the topology and its
deduction, compiles the deduction into a program (:mod:`linmstmm.program`),
releases statically indeterminate unknowns, counts the rigid-body modes, and
builds the Wittrick–Williams counter's reduced matrices, and the predictions
assemble a coarse FE model: on the launcher about 8 ms of a 13 ms solve of its
ten lowest frequencies, twice the search itself. A :class:`~linmstmm.model.Model` cannot
change (it is frozen, its arrays read-only), so all of that is made once per
model object and kept (:func:`compiled_system`); every solve still evaluates,
polishes and counts afresh — nothing that depends on ω is kept between solves.
The last MODELS_KEPT models are kept (a parameter sweep's thousand models do
not pile up); :func:`forget_compiled_models` drops them all. The coarse FE
pencil that predicts the roots is kept the same way
(:func:`linmstmm.coarse_prediction.coarse_pencil`).
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

from linmstmm.coarse_prediction import coarse_pencil, predicted_modes
from linmstmm.collector import collector_paused
from linmstmm.counting import count_in_disc
from linmstmm.deduction import Deduction
from linmstmm.determinant import (
    FREQUENCIES_ASSUMED,
    KERNELS_PAY_FROM,
    PREDICTED_FIXED,
    PREDICTED_PAY_FROM,
    carried_alone,
    determinant,
    kernels_compiled,
    kernels_loaded,
    load_kernels,
    resolved_engine,
    weight_at_most,
)
from linmstmm.model import Model
from linmstmm.model_structure import MODELS_KEPT, forget_structures
from linmstmm.nullspace import characteristic_frequencies, release_indeterminate
from linmstmm.rigid_motion import held_still, rigid_body_mode_count
from linmstmm.roots.settings import FLOOR_RATIO, predictions_wanted
from linmstmm.topology import build_topology
from linmstmm.wittrick_williams import ModeCounter, late_counter, mode_counter, too_large_to_count

@dataclass(frozen=True, eq=False)
class CompiledSystem:
    """What the root search of one model needs before its first frequency.

    Attributes
    ----------
    deduction : Deduction
        The deduced system, indeterminate unknowns released.
    determinant : CompiledDeterminant or NumpyDeterminant
        det Ū_all of ``deduction`` (:func:`linmstmm.determinant.determinant`);
        its ``evaluations`` keep counting across solves.
    released : int
        Statically indeterminate unknowns released.
    rigid_body_modes : int
        Zero-frequency modes (:func:`~linmstmm.rigid_motion.rigid_body_mode_count`).
    rigid_zeros_confirmed : bool
        True where the disc of the search's floor holds exactly the rigid-body
        modes' 2r zeros of det Ū_all, which the search then divides out
        (:meth:`linmstmm.roots.RootFinder.divide_out_rigid_body_zeros`).
    scale : float
        rad/s, the model's own frequency scale (the lowest of its
        :func:`~linmstmm.nullspace.characteristic_frequencies`).
    counter : ModeCounter or None
        The Wittrick–Williams counter (:func:`~linmstmm.wittrick_williams.mode_counter`).
    late_counter : callable or None
        For a model with no ``counter``: () -> its counter up to a larger order, made
        on the first call, or None (:func:`~linmstmm.wittrick_williams.late_counter`).
    """

    deduction: Deduction
    determinant: object
    released: int
    rigid_body_modes: int
    rigid_zeros_confirmed: bool
    scale: float
    counter: ModeCounter | None
    late_counter: Callable[[], ModeCounter | None] | None


def compiled_system(model: Model, root: str | None = None, cut_at=(), engine: str = "auto",
                    frequencies: int = FREQUENCIES_ASSUMED, predicted: bool = False) -> CompiledSystem:
    """The :class:`CompiledSystem` of ``model``: made on the first call for this model
    object (and root, cuts, engine), the same object after.

    Parameters
    ----------
    model : Model
        The model.
    root, cut_at : str or None, iterable of str
        See :func:`linmstmm.topology.build_topology`.
    engine : str
        "auto", "numpy" or "compiled" (:func:`linmstmm.determinant.determinant`; a
        system made for "auto" before the kernels were loaded is not taken for one
        made after). Where the numpy carry would take longer than the kernels'
        start-up to find ``frequencies`` of ``model``
        (:func:`~linmstmm.determinant.kernels_pay`; another line for a search polishing
        predictions without a counter, :func:`_kernels_pay`), "auto" loads
        them first, and a later call for the same model, finding them loaded, makes its
        system once more.
    frequencies : int
        Natural frequencies the solve asks for (what the kernels would save grows with them).
    predicted : bool
        Whether the search is for the lowest ``frequencies`` from the coarse predictions
        (a count without guesses), not a scan of a range.

    Returns
    -------
    CompiledSystem
    """
    resolved_engine(engine)  # an unknown engine is refused before anything is built
    key = (model, root, tuple(cut_at))
    try:
        if (engine == "auto" and not kernels_loaded()
                and weight_at_most(model) * (frequencies + PREDICTED_FIXED) >= KERNELS_PAY_FROM  # (either line)
                and _kernels_pay(key, frequencies, predicted)):
            load_kernels()  # a large request: the kernels' start-up costs less than the numpy carry's solve
        return _compiled(*key, engine, kernels_loaded())
    finally:
        _HANDED.pop(key, None)  # not taken where the system was kept already


def _kernels_pay(key: tuple, frequencies: int, predicted: bool) -> bool:
    """Whether the kernels pay for a solve of the (model, root, cut_at) ``key`` asking for
    ``frequencies``, where they are compiled on this machine: the elements carried one at a
    time times ``frequencies`` reach KERNELS_PAY_FROM, or, where the search (``predicted``)
    polishes predictions without a Wittrick–Williams counter
    (:func:`_polished_without_counter`, whose predictions the solve then takes as made
    here), those elements times (``frequencies`` + PREDICTED_FIXED) reach PREDICTED_PAY_FROM."""
    if not kernels_compiled():
        return False
    model, carried = key[0], _carried_alone(*key)
    scan_pays = carried * frequencies >= KERNELS_PAY_FROM
    if not predicted:
        return scan_pays
    predicted_pays = carried * (frequencies + PREDICTED_FIXED) >= PREDICTED_PAY_FROM
    if predicted_pays == scan_pays:  # the same either way: no prediction needed to decide
        return scan_pays
    return predicted_pays if _polished_without_counter(model, frequencies) else scan_pays


def _polished_without_counter(model: Model, frequencies: int) -> bool:
    """Whether the search for the lowest ``frequencies`` of ``model`` polishes its coarse
    predictions (:func:`~linmstmm.coarse_prediction.predicted_modes`, made and kept for the
    solve) and has no Wittrick–Williams counter for certain
    (:func:`~linmstmm.wittrick_williams.too_large_to_count`: a model with one counts and
    refines by the numpy engine too, which the kernels make far cheaper): there are as
    many predictions."""
    if not too_large_to_count(model):
        return False
    return predicted_modes(model, predictions_wanted(frequencies)).values.size >= frequencies


#: (model, root, cut_at) -> a Deduction built to decide the engine (:func:`_carried_alone`),
#: which the build of the system that follows takes instead of building its own.
_HANDED: dict = {}


@functools.lru_cache(maxsize=MODELS_KEPT)
def _carried_alone(model: Model, root: str | None, cut_at: tuple) -> int:
    """:func:`~linmstmm.determinant.carried_alone` of ``model``, decided once per model
    object; the deduction it is decided on is handed to the system's build (:data:`_HANDED`)."""
    deduction = Deduction(build_topology(model, root=root, cut_at=cut_at))
    _HANDED[model, root, cut_at] = deduction
    return carried_alone(deduction)


@functools.lru_cache(maxsize=MODELS_KEPT)
def _compiled(model: Model, root: str | None, cut_at: tuple, engine: str, loaded: bool) -> CompiledSystem:
    """:func:`compiled_system` made anew (a Model hashes by identity; ``loaded``: whether
    the kernels were loaded, which "auto" follows)."""
    with collector_paused():  # tens of thousands of new objects for a large model
        return _compiled_now(model, root, cut_at, engine)


def _compiled_now(model: Model, root: str | None, cut_at: tuple, engine: str) -> CompiledSystem:
    """The :class:`CompiledSystem` of ``model``, built (on the deduction the engine was
    decided on, where one was built for that)."""
    deduction = _HANDED.pop((model, root, cut_at), None)
    if deduction is None:
        deduction = Deduction(build_topology(model, root=root, cut_at=cut_at))
    evaluator = determinant(deduction, engine)  # compiled first: its plain Ū_all screens the probes
    scales = characteristic_frequencies(deduction.topology)  # of the elements alone: a release keeps them
    released = release_indeterminate(deduction, screen=evaluator.plain_matrix, scales=scales)
    if released:  # the program carries the unknowns it was compiled for
        evaluator = determinant(deduction, engine)
    rigid = 0 if held_still(deduction) else rigid_body_mode_count(model)
    scale = min(scales)
    confirmed = bool(rigid) and count_in_disc(evaluator.log_det, FLOOR_RATIO * scale) == 2 * rigid
    counter = mode_counter(model, engine)
    late = None if counter is not None else late_counter(model, engine)
    return CompiledSystem(deduction, evaluator, released, rigid, confirmed, scale, counter, late)


def forget_compiled_models() -> None:
    """Drop every compiled system, program walk (:func:`linmstmm.program.compile_program`),
    coarse FE pencil, count's elimination plan and whatever is kept by a model's
    structure (:mod:`linmstmm.model_structure`) so far: the next solve of any model
    compiles it anew, as in a new process (the benchmarks time first solves so)."""
    _compiled.cache_clear()
    _carried_alone.cache_clear()
    coarse_pencil.cache_clear()
    forget_structures()  # the program walks, count plans and all else kept by structure
