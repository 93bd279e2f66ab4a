"""Model updating: chosen model values fitted to measured natural frequencies.

The unknowns are model values named by keys (:mod:`linmstmm.parameters`), each
bounded by a range. The residuals are the relative frequency errors
``f_model / f_measured − 1`` of the measured modes, so that no decision
depends on the units the frequencies are given in; each unknown is scaled by
the larger magnitude of its range's ends for the same reason. Every
evaluation is one solve of the edited model
(:func:`linmstmm.sweep.solve_step`: frequencies, mode shapes and the
analytic ∂f/∂value of :mod:`linmstmm.sensitivity`, which is the Jacobian),
minimised by :func:`scipy.optimize.least_squares`.

Pairing: the measured modes (ascending) are the model's lowest elastic modes
in frequency order; when measured shapes are given (components at model
points), each measured mode is the model mode of the assignment that
maximises the sum of the MACs, among the starting model's modes up to
PAIRING_SPAN times the highest measured frequency (at least twice as many
modes as measured). Within a repeated frequency the sensitivities are those
of its ascending branches, not of a measured shape: a fit by shapes should
start where the paired frequencies are simple.

Confidence: 1-sigma intervals from the Jacobian at the solution, the
covariance s² (JᵀJ)⁻¹ with s² the residual sum of squares over the degrees
of freedom (measured modes − unknowns; none left: no interval).
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass

import numpy as np

from linmstmm.model import Model, ModelError, model_file
from linmstmm.parameters import get_value, parse_key, unit, with_values
from linmstmm.sweep import ENGINE, solve_step

#: Shape components a measured-shapes column may name, in the order of a point's 6 values.
DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")
#: The header cell of the measured frequencies' column.
FREQUENCY_COLUMN = "frequency [Hz]"
#: A measured file with one of these suffixes is a universal file (dataset 55 modes).
UFF_SUFFIXES = (".uff", ".unv")
#: Shapes are paired among the model modes up to this multiple of the highest measured frequency.
PAIRING_SPAN = 1.5
#: Relative change of the cost, of the unknowns and gradient size at which the fit stops.
TOLERANCE = 1e-14


@dataclass(frozen=True)
class Bounds:
    """One fitted key, bounded by ``lower`` and ``upper`` (SI, the key's unit)."""

    key: str
    lower: float
    upper: float

    @classmethod
    def parse(cls, text: str) -> Bounds:
        """``KEY=START:STOP`` (ValueError if malformed or START >= STOP).

        Parameters
        ----------
        text : str
            The range as written on the command line.

        Returns
        -------
        Bounds
        """
        key, equals, spec = text.partition("=")
        parts = spec.split(":")
        if not (equals and key and len(parts) == 2):
            raise ValueError(f"{text!r} is not KEY=START:STOP")
        try:
            lower, upper = float(parts[0]), float(parts[1])
        except ValueError:
            raise ValueError(f"{text!r}: START and STOP must be numbers") from None
        if not (math.isfinite(lower) and math.isfinite(upper) and lower < upper):
            raise ValueError(f"{text!r}: START and STOP must be finite, START < STOP")
        return cls(key, lower, upper)


@dataclass(frozen=True, eq=False)
class Measured:
    """Measured modes: ``frequencies_hz`` (m,) Hz, ascending; ``shapes`` (m, c) the
    components ``columns`` ((point, direction index) each) of each mode, or None."""

    frequencies_hz: np.ndarray
    shapes: np.ndarray | None = None
    columns: tuple[tuple[str, int], ...] = ()


def read_measured(path, model: Model) -> Measured:
    """The measured modes of a CSV file, or of a universal file (``.uff``, ``.unv``).

    CSV: one row per mode; a column ``frequency [Hz]``, and optionally one column
    per measured shape component named ``POINT.DIR`` (a point of ``model``,
    DIR one of x, y, z, rx, ry, rz). Lines starting with ``#`` are comments.
    Universal file: datasets 55 (normal modes) on nodes that are the model's
    points in order (:func:`linmstmm.uff.read_uff_modes`), e.g. as ``modes --uff``
    writes them.

    Parameters
    ----------
    path : str or Path
        The CSV file.
    model : Model
        The model whose points the shape columns name.

    Returns
    -------
    Measured
        The modes in ascending order of frequency.

    Raises
    ------
    ModelError
        Naming the file for a file it cannot read, and the column for a missing frequency column, an
        unknown point or direction, or a cell that is not a number (or a
        frequency that is not positive).
    """
    if str(path).lower().endswith(UFF_SUFFIXES):
        return _measured_uff(path, model)
    try:
        with open(path, newline="") as stream:
            rows = [row for row in csv.reader(stream) if row and not row[0].lstrip().startswith("#")]
    except OSError as error:
        raise ModelError(str(path), f"cannot read the measured file: {error.strerror or error}") from None
    if not rows or FREQUENCY_COLUMN not in [cell.strip() for cell in rows[0]]:
        raise ModelError(str(path), f"needs a column {FREQUENCY_COLUMN!r} (one row per measured mode)")
    header = [cell.strip() for cell in rows[0]]
    if any(len(row) != len(header) for row in rows[1:]):
        raise ModelError(str(path), f"every row needs the {len(header)} cells of the header")
    columns = [_shape_column(path, model, cell) for cell in header if cell != FREQUENCY_COLUMN]
    table = np.array([[_number(path, name, cell) for name, cell in zip(header, row)] for row in rows[1:]])
    table = table.reshape(len(rows) - 1, len(header))  # (modes, columns), also for no mode
    frequencies = table[:, header.index(FREQUENCY_COLUMN)]
    if not frequencies.size or not np.all(frequencies > 0):
        raise ModelError(str(path), "needs at least one measured mode, every frequency > 0",
                         key=FREQUENCY_COLUMN)
    order = np.argsort(frequencies, kind="stable")
    shapes = np.delete(table, header.index(FREQUENCY_COLUMN), axis=1)[order] if columns else None
    return Measured(frequencies[order], shapes, tuple(columns))


def _measured_uff(path, model: Model) -> Measured:
    """:class:`Measured` from a universal file, modes in ascending order of frequency."""
    from linmstmm.uff import read_uff_modes

    frequencies, shapes, columns = read_uff_modes(path, model)
    if not np.all(frequencies > 0):
        raise ModelError(str(path), "every measured frequency must be > 0", key="freq")
    order = np.argsort(frequencies, kind="stable")
    return Measured(frequencies[order], shapes[order], columns)


def _shape_column(path, model: Model, cell: str) -> tuple[str, int]:
    """(point, direction index) a ``POINT.DIR`` header cell names (ModelError if none)."""
    point, _, direction = cell.rpartition(".")
    if point not in model.points or direction not in DIRECTIONS:
        raise ModelError(str(path), f"a shape column is POINT.DIR with a point of the model and DIR one of "
                                    f"{', '.join(DIRECTIONS)}", key=cell)
    return point, DIRECTIONS.index(direction)


def _number(path, column: str, cell: str) -> float:
    """A CSV cell as a float (ModelError naming the file and column if it is not one)."""
    try:
        value = float(cell)
    except ValueError:
        raise ModelError(str(path), f"{cell!r} is not a number", key=column) from None
    if not math.isfinite(value):
        raise ModelError(str(path), f"{cell!r} is not a finite number", key=column)
    return value


@dataclass(frozen=True, eq=False)
class FitResult:
    """A fit of model values to measured frequencies.

    keys, units : the fitted keys and their SI units. initial, fitted, sigma :
    (n,) the model's values, the fitted values and their 1-sigma intervals (nan
    where the measured modes leave no degree of freedom or do not determine the value).
    measured_hz, fitted_hz : (m,) the measured frequencies and those of the fitted
    model's modes paired with them (``ranks``: their ranks, from 0). mac : (m,) MAC of
    each pair, or None without measured shapes. evaluations : solves of the model.
    converged : whether least_squares met its tolerances. message : what it said.
    """

    model: str
    keys: tuple[str, ...]
    units: tuple[str, ...]
    initial: np.ndarray
    fitted: np.ndarray
    sigma: np.ndarray
    measured_hz: np.ndarray
    fitted_hz: np.ndarray
    ranks: np.ndarray
    mac: np.ndarray | None
    evaluations: int
    converged: bool
    message: str

    def to_dict(self) -> dict:
        """The ``linmstmm fit --json`` object (``docs/cli.md``); nan is null.

        Returns
        -------
        dict
            ``model``, ``parameters`` (per key: unit, initial, fitted, sigma),
            ``measured_hz``, ``fitted_hz``, ``ranks``, ``mac``, ``evaluations``,
            ``converged``, ``message``.
        """
        return {
            "model": self.model,
            "parameters": [{"key": k, "unit": u, "initial": float(i), "fitted": float(f), "sigma": _json(s)}
                           for k, u, i, f, s in zip(self.keys, self.units, self.initial, self.fitted, self.sigma)],
            "measured_hz": self.measured_hz.tolist(), "fitted_hz": self.fitted_hz.tolist(),
            "ranks": self.ranks.tolist(), "mac": None if self.mac is None else self.mac.tolist(),
            "evaluations": self.evaluations, "converged": self.converged, "message": self.message,
        }


def fit(model: Model, measured: Measured, bounds, engine: str = ENGINE) -> FitResult:
    """Fit the values of ``bounds`` so that ``model``'s frequencies match ``measured``.

    Parameters
    ----------
    model : Model
        The model; its values are the starting point.
    measured : Measured
        The measured modes (:func:`read_measured`).
    bounds : sequence of Bounds
        The fitted keys and their ranges (SI); the model's value of each must lie inside.
    engine : str
        How det Ū_all is evaluated ("numpy", "compiled" or "auto": at each solve as
        :func:`~linmstmm.solve.natural_frequencies` resolves it).

    Returns
    -------
    FitResult

    Raises
    ------
    ModelError
        For an unknown key, a key varied twice or a model value outside its
        range, and for a key without an analytic sensitivity (points, spring axes).
    """
    from scipy.optimize import least_squares  # here: importing scipy.optimize costs every command 0.1 s

    problem = _Problem(model, measured, list(bounds), engine)
    solution = least_squares(problem.residuals, problem.start, jac=problem.jacobian,
                             bounds=(problem.lower, problem.upper), method="trf",
                             xtol=TOLERANCE, ftol=TOLERANCE, gtol=TOLERANCE)
    step, ranks = problem.solved(solution.x)
    return FitResult(model.name, tuple(b.key for b in problem.bounds), tuple(unit(k) for k in problem.keys),
                     problem.start * problem.scales, solution.x * problem.scales,
                     _sigma(solution.fun, solution.jac) * problem.scales, measured.frequencies_hz,
                     step.frequencies_hz[ranks], ranks, problem.mac(step, ranks), problem.evaluations,
                     bool(solution.success), str(solution.message))


class _Problem:
    """The residuals and Jacobian of a fit, in scaled unknowns x = value / scale; one solve
    per distinct x (least_squares asks for the residuals and the Jacobian at the same x)."""

    def __init__(self, model: Model, measured: Measured, bounds: list, engine: str):
        self.model, self.measured, self.bounds, self.engine = model, measured, bounds, engine
        self.keys = [parse_key(model, b.key) for b in bounds]
        if len({k.text for k in self.keys}) < len(self.keys):
            raise ModelError(model_file(model), "a key is fitted twice: " + ", ".join(b.key for b in bounds))
        self.scales = np.array([max(abs(b.lower), abs(b.upper)) for b in bounds])
        self.lower = np.array([b.lower for b in bounds]) / self.scales
        self.upper = np.array([b.upper for b in bounds]) / self.scales
        values = np.array([get_value(model, key) for key in self.keys])
        for b, value in zip(bounds, values):
            if not b.lower <= value <= b.upper:
                raise ModelError(model_file(model), f"the model's value {value:g} is not inside the range "
                                               f"{b.lower:g}:{b.upper:g} to fit in", key=b.key)
        self.start = values / self.scales
        self.evaluations = 0
        self._last = None
        self.count = measured.frequencies_hz.size
        if measured.shapes is not None:
            self.count = self._pairing_count()

    def _pairing_count(self) -> int:
        """Model modes to pair measured shapes among: from twice the measured ones, doubled
        until they reach PAIRING_SPAN times the highest measured frequency (or the model's last)."""
        count, top = 2 * self.count, PAIRING_SPAN * self.measured.frequencies_hz[-1]
        while True:
            found = self._solve(self.start, count).frequencies_hz
            if found.size < count or found[-1] > top:
                return count
            count *= 2

    def solved(self, x):
        """(StepSolution of the model at x, (m,) ranks of the model modes paired with the measured)."""
        if self._last is None or not np.array_equal(self._last[0], x):
            step = self._solve(x, self.count)
            self._last = (np.array(x), step, self._paired(step))
        return self._last[1], self._last[2]

    def _solve(self, x, count: int):
        """StepSolution of the lowest ``count`` modes of the model at x, with the sensitivities."""
        edited = with_values(self.model, dict(zip(self.keys, x * self.scales)))
        self.evaluations += 1
        return solve_step(edited, count, [k.text for k in self.keys], self.engine)

    def residuals(self, x) -> np.ndarray:
        """(m,) f_model / f_measured − 1 of the paired modes."""
        step, ranks = self.solved(x)
        return step.frequencies_hz[ranks] / self.measured.frequencies_hz - 1

    def jacobian(self, x) -> np.ndarray:
        """(m, n) ∂residual/∂x from the analytic sensitivities."""
        step, ranks = self.solved(x)
        return np.column_stack([step.sensitivities[key.text][ranks] * scale / self.measured.frequencies_hz
                                for key, scale in zip(self.keys, self.scales)])

    def mac(self, step, ranks) -> np.ndarray | None:
        """(m,) MAC of each measured shape with its paired model mode (None without shapes)."""
        if self.measured.shapes is None:
            return None
        return np.diag(self._macs(step)[:, ranks]).copy()

    def _paired(self, step) -> np.ndarray:
        """Ranks of the model modes paired with the measured ones (see the module docstring)."""
        m = self.measured.frequencies_hz.size
        if step.frequencies_hz.size < m:
            raise ModelError(model_file(self.model), f"the model has {step.frequencies_hz.size} elastic modes, "
                                                f"fewer than the {m} measured")
        if self.measured.shapes is None:
            return np.arange(m)
        from scipy.optimize import linear_sum_assignment  # as least_squares: kept off start-up

        rows, ranks = linear_sum_assignment(self._macs(step), maximize=True)
        return ranks[np.argsort(rows)]

    def _macs(self, step) -> np.ndarray:
        """(m, modes) MAC between the measured shapes and the model's at the measured components."""
        from linmstmm.modes import mac_matrix

        points = list(self.model.points)
        model_shapes = np.stack([step.shapes[:, points.index(p), d] for p, d in self.measured.columns], axis=1)
        moving = np.any(model_shapes != 0, axis=1)  # a mode still at every measured component pairs with none
        macs = np.zeros((self.measured.frequencies_hz.size, model_shapes.shape[0]))
        macs[:, moving] = mac_matrix(self.measured.shapes, model_shapes[moving])
        return macs


#: A singular value of the Jacobian (scaled unknowns, relative frequencies) below this
#: fraction of the largest is a direction the data do not determine.
UNDETERMINED = 1e-8
#: An unknown with a component above this in such a direction has no 1-sigma (null).
FREE_COMPONENT = 1e-6


def _sigma(residuals: np.ndarray, jacobian: np.ndarray) -> np.ndarray:
    """(n,) 1-sigma of the scaled unknowns: √diag(s² (JᵀJ)⁻¹), s² = Σr² / (m − n); nan where
    no degree of freedom is left, and for every unknown the data do not determine: one
    with a part in a direction J's singular values leave below UNDETERMINED of the
    largest (E and ρ of a beam enter its frequencies only as E/ρ: JᵀJ is singular
    to rounding, and its inverse gave a finite 1.5e5 Pa)."""
    m, n = jacobian.shape
    if m <= n:
        return np.full(n, np.nan)
    _, singular, vt = np.linalg.svd(jacobian, full_matrices=True)
    kept = singular > UNDETERMINED * singular.max(initial=0.0)
    if not kept.any():
        return np.full(n, np.nan)
    variance = (residuals @ residuals) / (m - n)
    sigma = np.sqrt(variance * ((vt[:kept.sum()] / singular[kept, None]) ** 2).sum(axis=0))
    free = np.abs(vt[kept.sum():]).max(axis=0, initial=0.0) > FREE_COMPONENT
    return np.where(free, np.nan, sigma)


def _json(value: float):
    """A float for JSON, nan as None."""
    return None if math.isnan(value) else float(value)
