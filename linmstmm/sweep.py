"""Parameter studies: natural frequencies over a grid of model values, modes tracked by MAC.

A sweep is a list of steps, each a dict key -> value (keys:
:mod:`linmstmm.parameters`). :func:`grid` builds it from :class:`Vary`
ranges, as their outer product or (``zipped``) side by side; the firing
scenes of :mod:`linmstmm.scenes` are another list of steps. Each step is an
edited copy of the model, solved once by :func:`~linmstmm.modes.mode_shapes`
(its frequencies are those of :func:`~linmstmm.solve.natural_frequencies` to
the last digit; its shapes serve the tracking and the sensitivities of
:mod:`linmstmm.sensitivity`). By default from a cold start, with the engine
"auto" resolved once, in the calling process, for the whole sweep (:data:`ENGINE`):
every runner then uses that engine, and every row is exactly what
``natural_frequencies(edited model, engine=result.engine)`` gives, whatever runs
the steps. A short sweep of a launcher-size model runs on the numpy carry, as
``linmstmm freqs`` does in a new process; a long one loads the compiled kernels
(:func:`~linmstmm.determinant.kernels_pay`, counting the steps).

An option that trades the bits of a cold start (the roots agree to rounding) for
speed: ``warm_start`` starts each step's root
search from the frequencies of its neighbour in the grid (below) where they
are the better starts, else from the step's own coarse predictions
(:mod:`linmstmm.warm_starts`), so a step waits for its neighbour and the
parallelism is that of the grid's tracking tree (a single line runs in order).

Tracking (:mod:`linmstmm.tracking`): each step is compared by MAC with its
neighbour in the grid (the step one before it along the last range that is
not at its start). Column c at step s is rank ``order[s, c]`` there; repeated
frequencies keep one column per multiplicity.

Steps run serially, in local processes (``workers``) or on a dask.distributed
cluster (``dask``); the results are the same.
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field, replace
from functools import partial

import numpy as np

from linmstmm.deduction import Deduction
from linmstmm.determinant import engine_for, kernels_loaded, kernels_pay, resolved_engine
from linmstmm.model import Model, ModelError
from linmstmm.parameters import get_value, parse_key, with_values
from linmstmm.results import Result, decode_array, decode_arrays
from linmstmm.sweep_runners import run_steps
from linmstmm.topology import build_topology
from linmstmm.tracking import SAME_MODE_MAC, length_scale, track
from linmstmm.warm_starts import largest_difference, prediction_error, trend, warm_starts

#: How every step evaluates det Ū_all unless told: "auto", resolved once in the calling
#: process (:func:`_step_engine`), so that a step gives the same bits in this process, in a
#: fresh worker process and on a cluster.
ENGINE = "auto"
#: Stations along each beam for the mode shapes of a step: its ends (a step's shapes are
#: read at the points; the points' displacements do not depend on the stations).
SHAPE_STATIONS = 2


@dataclass(frozen=True)
class Vary:
    """One swept key: ``n`` values from ``start`` to ``stop`` (both included),
    equally spaced, or in geometric progression if ``log``."""

    key: str
    start: float
    stop: float
    n: int
    log: bool = False

    @classmethod
    def parse(cls, text: str) -> Vary:
        """``KEY=START:STOP:N`` or ``KEY=START:STOP:N:log`` (ValueError if malformed)."""
        key, equals, spec = text.partition("=")
        parts = spec.split(":")
        log = parts[-1] == "log"
        if log:
            parts = parts[:-1]
        if not (equals and key and len(parts) == 3):
            raise ValueError(f"{text!r} is not KEY=START:STOP:N or KEY=START:STOP:N:log")
        try:
            start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
        except ValueError:
            raise ValueError(f"{text!r}: START and STOP must be numbers and N an integer") from None
        return cls(key, start, stop, n, log)

    def __post_init__(self):
        if not (math.isfinite(self.start) and math.isfinite(self.stop)):
            raise ValueError(f"{self.key}: START and STOP must be finite")
        if self.n < 1:
            raise ValueError(f"{self.key}: N must be at least 1, got {self.n}")
        if self.log and not (self.start > 0 and self.stop > 0):
            raise ValueError(f"{self.key}: logarithmic steps need START and STOP > 0")

    def values(self) -> np.ndarray:
        """(n,) the values, in the key's SI unit."""
        if self.log:
            return np.geomspace(self.start, self.stop, self.n)
        return np.linspace(self.start, self.stop, self.n)


def grid(varies, zipped: bool = False) -> tuple[list[dict], tuple[int, ...]]:
    """The steps of ``varies`` and the grid's shape.

    Parameters
    ----------
    varies : iterable of Vary
        The ranges, each with its own key.
    zipped : bool
        Pair the ranges (all must have the same N; shape (N,)) instead of
        their outer product (shape (n1, n2, ...), last range fastest).

    Returns
    -------
    steps : list of dict
        Each step's {key: value}.
    shape : tuple of int

    Raises
    ------
    ValueError
        For no range, a key varied twice, or zipped ranges of different N.
    """
    varies = list(varies)
    if not varies:
        raise ValueError("nothing to vary: give at least one range")
    keys = [v.key for v in varies]
    if len(set(keys)) < len(keys):
        raise ValueError(f"a key is varied twice: {', '.join(keys)}")
    columns = [v.values() for v in varies]
    if zipped:
        counts = {v.n for v in varies}
        if len(counts) > 1:
            raise ValueError("zipped ranges need the same N, got "
                             + ", ".join(f"{v.key}: {v.n}" for v in varies))
        rows, shape = zip(*columns), (varies[0].n,)
    else:
        rows, shape = itertools.product(*columns), tuple(v.n for v in varies)
    return [dict(zip(keys, map(float, row))) for row in rows], shape


def neighbours(shape: tuple[int, ...]) -> list[int | None]:
    """For each step of a grid, the step it is tracked from.

    Parameters
    ----------
    shape : tuple of int
        The grid's shape (last index fastest).

    Returns
    -------
    list of int or None
        Per step, the step one back along the last index that is not 0
        (None for the first step).
    """
    out = []
    for index in np.ndindex(*shape):
        moving = [axis for axis, i in enumerate(index) if i > 0]
        if not moving:
            out.append(None)
            continue
        back = list(index)
        back[moving[-1]] -= 1
        out.append(int(np.ravel_multi_index(back, shape)))
    return out


@dataclass(frozen=True, eq=False)
class StepSolution:
    """One step solved.

    frequencies_hz : (m,) elastic natural frequencies, Hz, ascending (m = count
    unless fewer exist). rigid_body_modes : zero-frequency modes.
    shapes : (m, p, 6) mass-normalised mode shapes at the model's p points
    (m/√kg, rad/√kg). sensitivities : key -> (m,) ∂f/∂value, Hz per SI unit.
    note : what the solve had to say ("" if nothing).
    moved : largest relative change of the frequencies from those of the step it
    started from (nan without one). previous_hz : (m',) the frequencies of that step
    (None without one). trend_miss : largest relative difference of the frequencies
    from those the step it started from extrapolated (:func:`~linmstmm.warm_starts.trend`;
    nan where it could not). prediction_error : largest relative error of the
    coarse predictions (:func:`~linmstmm.coarse_prediction.predict_frequencies`) at
    the frequencies of the first step of its chain of warm starts (nan where not
    measured). The next step chooses its starts by both
    (:func:`~linmstmm.warm_starts.warm_starts`).
    """

    frequencies_hz: np.ndarray
    rigid_body_modes: int
    shapes: np.ndarray
    sensitivities: dict = field(default_factory=dict)
    note: str = ""
    moved: float = math.nan
    previous_hz: np.ndarray | None = None
    trend_miss: float = math.nan
    prediction_error: float = math.nan


def solve_step(model: Model, count: int, sensitivity_keys=(), engine: str = ENGINE,
               start: StepSolution | None = None, with_shapes: bool = True,
               chained: bool = False) -> StepSolution:
    """Frequencies, mode shapes and sensitivities of one step, from one solve.

    Parameters
    ----------
    model : Model
        The step's (edited) model.
    count : int
        Elastic frequencies wanted.
    sensitivity_keys : sequence of str
        Keys whose ∂f/∂value is wanted (none: no mode-shape derivatives).
    engine : str
        How det Ū_all is evaluated, as for :func:`~linmstmm.solve.natural_frequencies`.
    start : StepSolution or None
        A neighbouring step whose frequencies start the root search where they are
        the better starts (:func:`~linmstmm.warm_starts.warm_starts`; None: a cold start).
    with_shapes : bool
        False: the frequencies alone (by :func:`~linmstmm.solve.natural_frequencies`,
        the same roots), shapes (m, 0, 6); not with ``sensitivity_keys``.
    chained : bool
        The step is one of a sweep with warm starts: the first of its chain (no
        ``start``) measures the coarse predictions' error at its roots for the steps
        that follow (:attr:`StepSolution.prediction_error`).

    Returns
    -------
    StepSolution
        The frequencies as :func:`~linmstmm.solve.natural_frequencies` with
        ``engine`` (and ``guess_hz`` the frequencies of ``start`` where they are
        taken) gives them, the mass-normalised shapes at the points and the
        sensitivities.
    """
    solution = _solved_step(model, count, sensitivity_keys, engine, warm_starts(start), with_shapes)
    found = solution.frequencies_hz
    if start is not None:
        extrapolated = trend(start)
        missed = math.nan if extrapolated is None else largest_difference(extrapolated, found)
        return replace(solution, moved=largest_difference(start.frequencies_hz, found),
                       previous_hz=start.frequencies_hz, trend_miss=missed,
                       prediction_error=start.prediction_error)
    return replace(solution, prediction_error=prediction_error(model, count, found)) if chained else solution


def _solved_step(model: Model, count: int, sensitivity_keys, engine: str, guess_hz,
                 with_shapes: bool) -> StepSolution:
    """:func:`solve_step` from the starts ``guess_hz`` (Hz, or None: cold)."""
    from linmstmm.modes import mode_shapes
    from linmstmm.solve import natural_frequencies

    if not with_shapes and not sensitivity_keys:  # the shapes cost a launcher step as much as its roots
        result = natural_frequencies(model, count, engine=engine, guess_hz=guess_hz)
        found = result.frequencies_hz
        return StepSolution(found, result.rigid_body_modes, np.zeros((found.size, 0, 6)), note=result.note)
    modes = mode_shapes(model, count=count, stations=SHAPE_STATIONS, engine=engine, guess_hz=guess_hz)
    rigid = modes.rigid_body_modes
    elastic = slice(rigid, rigid + min(count, modes.omega.size - rigid))
    shapes = np.stack([modes.point_displacements[p][elastic] for p in model.points], axis=1)
    sensitivities = {}
    if sensitivity_keys:
        from linmstmm.sensitivity import frequency_sensitivities

        sensitivities = {key: values[elastic] for key, values in
                         frequency_sensitivities(model, modes, sensitivity_keys).items()}
    return StepSolution(modes.frequencies_hz[elastic], rigid, shapes, sensitivities, modes.note)


@dataclass(frozen=True, eq=False)
class SweepResult(Result):
    """A parameter study.

    keys : the varied keys. values : (steps, keys) their values, SI.
    shape : the grid's shape (steps = its product).
    frequencies_hz_by_rank : (steps, count) Hz, ascending per step (nan where
    fewer exist). order : (steps, count) int, the rank at each step of the mode
    each column follows (-1 where none). tracking_mac : (steps, count) MAC of
    each column's shape against its shape at the neighbouring step (1 at the first).
    sensitivities : key -> (steps, count) ∂f/∂value, Hz per SI unit of the key,
    in tracked order (empty without sensitivities).
    rigid_body_modes : (steps,) int. notes : step index -> note of its solve.
    seconds : wall time. workers : what ran the steps ("serial", "2 processes", ...).
    engine : "numpy" or "compiled", how every step evaluated det Ū_all.
    warm_start : whether each step started from its neighbour's frequencies.
    """

    model: str
    keys: tuple[str, ...]
    values: np.ndarray
    shape: tuple[int, ...]
    frequencies_hz_by_rank: np.ndarray
    order: np.ndarray
    tracking_mac: np.ndarray
    sensitivities: dict
    rigid_body_modes: np.ndarray
    notes: dict
    seconds: float
    workers: str
    engine: str
    warm_start: bool

    kind = "sweep"

    @property
    def frequencies_hz(self) -> np.ndarray:
        """(steps, count) Hz in tracked order: column c follows one mode shape."""
        return _tracked(self.frequencies_hz_by_rank, self.order)

    @property
    def switched(self) -> np.ndarray:
        """(steps, count) bool: where a column holds another mode than at the neighbouring
        step (its MAC there below SAME_MODE_MAC): the mode it followed left the lowest
        ``count``, and one that entered took its place."""
        with np.errstate(invalid="ignore"):
            return self.tracking_mac < SAME_MODE_MAC

    def to_dict(self) -> dict:
        """The ``linmstmm sweep --json`` object (``docs/cli.md``); nan is null."""
        return {
            "model": self.model, "keys": list(self.keys), "shape": list(self.shape),
            "values": self.values.tolist(),
            "frequencies_hz": _json_rows(self.frequencies_hz),
            "frequencies_hz_by_rank": _json_rows(self.frequencies_hz_by_rank),
            "order": self.order.tolist(), "tracking_mac": _json_rows(self.tracking_mac),
            "rigid_body_modes": self.rigid_body_modes.tolist(),
            **({"sensitivity_hz_per_unit": {k: _json_rows(v) for k, v in self.sensitivities.items()}}
               if self.sensitivities else {}),
            "notes": {str(step): note for step, note in self.notes.items()},
            "solves": len(self.values), "seconds": self.seconds, "workers": self.workers,
            "engine": self.engine, "warm_start": self.warm_start,
        }

    @classmethod
    def _from_data(cls, data: dict) -> SweepResult:
        """The result :meth:`to_dict` describes (which holds all of it; null is nan)."""
        return cls(data["model"], tuple(data["keys"]), decode_array(data["values"], ndim=2), tuple(data["shape"]),
                   decode_array(data["frequencies_hz_by_rank"], ndim=2), decode_array(data["order"], int, ndim=2),
                   decode_array(data["tracking_mac"], ndim=2),
                   decode_arrays(data.get("sensitivity_hz_per_unit", {}), ndim=2),
                   decode_array(data["rigid_body_modes"], int), {int(step): note for step, note in data["notes"].items()},
                   data["seconds"], data["workers"], data["engine"], data["warm_start"])

    def plot(self, log_x: bool = False):
        """The tracked frequencies against the first varied key (:func:`linmstmm.plot.sweep_figure`):
        a colour per tracked mode, a line per combination of the other keys' values.

        Parameters
        ----------
        log_x : bool
            A logarithmic axis of the key's values.

        Returns
        -------
        matplotlib.figure.Figure
            Not saved; matplotlib is imported on this call.
        """
        from linmstmm.plot import sweep_figure

        return sweep_figure(self, log_x)


def sweep(model: Model, steps, count: int = 5, shape=None, sensitivity: bool = False,
          workers: int = 1, dask=None, progress: bool = False, engine: str = ENGINE,
          warm_start: bool = False, track_modes: bool = True) -> SweepResult:
    """Natural frequencies of ``model`` at every step, modes tracked by MAC.

    Parameters
    ----------
    model : Model
        The model the steps edit.
    steps : list of dict
        Each step's {key: value} (every step sets the same keys), e.g. from :func:`grid`.
    count : int
        Elastic frequencies per step.
    shape : tuple of int or None
        The grid's shape (tracking follows its neighbours, :func:`neighbours`);
        default a line of the steps.
    sensitivity : bool
        Also ∂f/∂value of every varied key at every step
        (:func:`linmstmm.sensitivity.frequency_sensitivities`).
    workers : int
        Local processes running the steps (1: in this process).
    dask : str, distributed.Client or None
        Run the steps on a dask.distributed cluster instead: a scheduler
        address, "local" (a LocalCluster of ``max(workers, 2)`` single-threaded
        worker processes, closed at the end) or a ``distributed.Client``.
    progress : bool
        A tqdm bar on stderr (only when stderr is a terminal).
    engine : str
        How every step evaluates det Ū_all: "numpy", "compiled", or "auto": what a
        solve of ``model`` in this process would take
        (:func:`linmstmm.determinant.determinant`), and the kernels where the steps
        each process runs (``workers`` share them, a dask cluster is taken for
        ``max(workers, 2)``) carry elements enough that they pay for the kernels'
        start-up, once the kernels are compiled on this machine
        (:func:`linmstmm.determinant.kernels_pay`); the runners all use that engine.
    warm_start : bool
        Start each step's root search from the frequencies of its neighbour
        (:func:`neighbours`; found, then certified by a count as from a cold start),
        unless the last move seen between neighbours outran the coarse predictions'
        error (:func:`~linmstmm.warm_starts.warm_starts`: the step then starts from those).
    track_modes : bool
        False: no mode shapes (about half of a launcher step's cost) and no
        tracking: every column follows the rank (``order`` the ranks, ``tracking_mac``
        NaN); not with ``sensitivity``.

    Returns
    -------
    SweepResult

    Raises
    ------
    ModelError
        For an unknown key or a step that breaks the model contract.
    """
    start = time.perf_counter()
    steps = list(steps)
    shape = tuple(shape) if shape is not None else (len(steps),)
    _check_steps(steps, shape)
    processes = max(workers, 2) if dask is not None else workers  # each loads the kernels for itself
    engine = _step_engine(model, engine, count, -(-len(steps) // processes))
    keys = [parse_key(model, text) for text in steps[0]]
    models = [_edited(model, keys, step) for step in steps]
    names = tuple(key.text for key in keys)
    previous = neighbours(shape)
    if sensitivity and not track_modes:
        raise ValueError("sensitivities need the mode shapes: track_modes must be True")
    solve = partial(solve_step, count=count, sensitivity_keys=names if sensitivity else (), engine=engine,
                    with_shapes=track_modes, chained=warm_start)
    solutions, label = run_steps(models, solve, previous if warm_start else [None] * len(models),
                                 workers, dask, progress)
    if track_modes:
        order, mac = track([s.shapes for s in solutions], previous, count, length_scale(model))
    else:  # every column its rank
        found = np.array([s.frequencies_hz.size for s in solutions])[:, None]
        order = np.where(np.arange(count) < found, np.arange(count), -1)
        mac = np.full(order.shape, np.nan)
    return SweepResult(
        model.name, names, np.array([[get_value(m, key) for key in keys] for m in models]).reshape(-1, len(keys)),
        shape, _padded([s.frequencies_hz for s in solutions], count), order, mac,
        {name: _tracked(_padded([s.sensitivities[name] for s in solutions], count), order)
         for name in (names if sensitivity else ())},
        np.array([s.rigid_body_modes for s in solutions], dtype=int),
        {i: s.note for i, s in enumerate(solutions) if s.note}, time.perf_counter() - start, label,
        engine, warm_start)


def _step_engine(model: Model, engine: str, count: int, steps: int) -> str:
    """"numpy" or "compiled": ``engine`` as this process resolves it; "auto" as a solve of
    ``model`` here would resolve it (:func:`linmstmm.determinant.determinant`: numpy for a
    model mostly of repeated cells even with the kernels loaded), and taking the kernels
    where the ``steps`` solves of ``count`` frequencies each process runs carry elements
    enough (:func:`linmstmm.determinant.kernels_pay`)."""
    if engine != "auto":
        return resolved_engine(engine)
    deduction = Deduction(build_topology(model))
    if kernels_loaded():
        return engine_for(deduction, engine)
    return "compiled" if kernels_pay(deduction, count, steps) else "numpy"


def _check_steps(steps: list, shape: tuple) -> None:
    """ValueError unless there are steps, all setting the same keys, as many as ``shape`` holds."""
    if not steps or not steps[0]:
        raise ValueError("a sweep needs at least one step setting at least one key")
    if any(set(step) != set(steps[0]) for step in steps):
        raise ValueError(f"every step must set the same keys: {', '.join(steps[0])}")
    if math.prod(shape) != len(steps):
        raise ValueError(f"shape {shape} does not hold {len(steps)} steps")


def _edited(model: Model, keys, step: dict) -> Model:
    """``model`` with the values of ``step``; a breach of the contract names the step."""
    try:
        return with_values(model, {key: step[key.text] for key in keys})
    except ModelError as error:
        where = ", ".join(f"{key.text} = {step[key.text]:g}" for key in keys)
        raise ModelError(error.file, f"{error.message} (in the step {where})",
                         element=error.element, key=error.key) from None


def _padded(rows, count: int) -> np.ndarray:
    """(steps, count) float rows, nan beyond each row's end."""
    out = np.full((len(rows), count), np.nan)
    for i, row in enumerate(rows):
        out[i, :len(row)] = row
    return out


def _tracked(by_rank: np.ndarray, order: np.ndarray) -> np.ndarray:
    """``by_rank`` (steps, count) in tracked column order (nan where a column has no mode)."""
    rows = np.arange(by_rank.shape[0])[:, None]
    return np.where(order >= 0, by_rank[rows, np.maximum(order, 0)], np.nan)


def _json_rows(array: np.ndarray) -> list:
    """A 2-D float array as lists, nan as None (JSON null)."""
    return [[None if math.isnan(v) else float(v) for v in row] for row in array]
