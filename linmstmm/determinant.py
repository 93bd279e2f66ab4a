"""det Ū_all(ω) of one deduction, by the numpy carry or the compiled kernels.

Both engines answer the same two questions with the same numbers (to
rounding): ``log_det(ω)`` — sign (phase, for complex ω) and log|det Ū_all| —
and ``matrix(ω)`` — the orthonormalised Ū_all whose differences are smooth in
ω (Newton's pencil); both count their evaluations (one per frequency, per thread), the
cost figure the benchmarks report per root. The compiled one also gives
``plain_matrix(ω)``, Ū_all as the unknowns stand (no orthonormalisation, not
counted), with which :func:`linmstmm.nullspace.release_indeterminate` screens
its probes for statically indeterminate unknowns (``plain_matrix`` is None for
the numpy carry, which reads them itself); a compiled determinant serves the
unknowns it was compiled for, so after a release it is compiled anew.

* :class:`NumpyDeterminant` — :meth:`Deduction.log_det` / :meth:`Deduction.matrix`,
  vectorised over a stack of frequencies (a run of identical cells by powers of
  the cell matrix); the readable reference.
* :class:`CompiledDeterminant` — the deduction compiled once into a program
  (:mod:`linmstmm.program`) replayed by numba kernels (:mod:`linmstmm._kernels`):
  about five times cheaper per evaluation, but numba's start-up costs a new
  process 0.5-1.5 s (its import and the first call that loads the cached
  machine code), more than a launcher-size solve of 10 to 100 frequencies
  spends in the numpy carry altogether.

:func:`determinant` chooses: ``engine="auto"`` takes the compiled kernels
where they are already loaded in this process (a long session, a parameter
study: :func:`load_kernels`), the numpy carry otherwise, and for a model
made mostly of one repeated cell (a long chain), whose runs the numpy carry
powers. A request large enough that its numpy solve would cost more than the
kernels' start-up (the model's elements times the frequencies asked for, times a
sweep's steps: :func:`kernels_pay`, asked by
:func:`linmstmm.compiled_model.compiled_system` and :func:`linmstmm.sweep.sweep`)
has them loaded for it.
"""
from __future__ import annotations

import os
import sys
import threading
from pathlib import Path

import numpy as np

from linmstmm.deduction import Deduction
from linmstmm.program import compile_program
from linmstmm.spread import spread

ENGINES = ("auto", "numpy", "compiled")


def kernels_loaded() -> bool:
    """True once the compiled kernels are loaded in this process."""
    return "linmstmm._kernels" in sys.modules


def load_kernels() -> None:
    """Import numba and the compiled kernels now (compiling them on the first run
    on this machine), so that ``engine="auto"`` uses them from here on."""
    import linmstmm._kernels  # noqa: F401
    import linmstmm._stiffness_kernels  # noqa: F401  (the Wittrick–Williams count's)


def resolved_engine(engine: str) -> str:
    """The engine ``engine`` stands for in this process now (before the model is looked at:
    see :func:`determinant`).

    Parameters
    ----------
    engine : str
        "auto", "numpy" or "compiled".

    Returns
    -------
    str
        "numpy" or "compiled": "auto" is "compiled" once the kernels are loaded
        here (:func:`load_kernels`), "numpy" before.

    Raises
    ------
    ValueError
        For an engine not in ENGINES.
    """
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    if engine == "auto":
        return "compiled" if kernels_loaded() else "numpy"
    return engine


def determinant(deduction: Deduction, engine: str = "auto"):
    """The determinant of ``deduction`` by ``engine`` ("auto", "numpy" or "compiled").

    "auto" is the compiled kernels once they are loaded (:func:`resolved_engine`),
    except for a model made mostly of a repeated cell
    (:func:`repeated_cells_dominate`), which only the numpy carry takes by powers
    of the cell's matrix.
    """
    chosen = engine_for(deduction, engine)
    return CompiledDeterminant(deduction) if chosen == "compiled" else NumpyDeterminant(deduction)


def engine_for(deduction: Deduction, engine: str) -> str:
    """"numpy" or "compiled": what :func:`determinant` evaluates ``deduction`` by for
    ``engine`` in this process now (:func:`resolved_engine`; "auto" keeps the numpy carry for
    a model made mostly of a repeated cell, :func:`repeated_cells_dominate`)."""
    chosen = resolved_engine(engine)
    if chosen == "compiled" and engine == "auto" and repeated_cells_dominate(deduction):
        return "numpy"
    return chosen


#: Frequencies asked for times the elements the numpy carry takes one at a time (each beam
#: counted BEAM_WEIGHT times), over all the solves the kernels would serve, from which
#: ``engine="auto"`` loads the kernels in a process that has not (:func:`kernels_pay`): the
#: numpy carry's work grows with both, the kernels' start-up (0.5-1.1 s) does not. Measured
#: end to end, ``linmstmm freqs FILE --count C`` in new processes, numpy against the kernels
#: (cached), best of 2, while those models were searched by the scan (as a round
#: cantilever's double roots still are; PREDICTED_PAY_FROM for the searches from
#: predictions that replaced it): cantilevers of 100 beam elements, C = 5, 10, 20, 40: 0.82/1.36,
#: 0.70/1.20, 0.81/1.27, 1.23/1.51 s; of 200: 0.85/1.12, 0.99/1.10, 1.81/1.32, 3.26/1.65 s;
#: of 300: 1.15/1.23, 1.57/1.15, 2.44/1.37, 17.7/1.75 s (the numpy carry's 6,677 evaluations
#: of a scan above the predictions' reach); earlier, best of 5 to 11: 500 beam elements
#: C = 3 1.71/1.87 s, 10 2.68/1.54 s; 1,000, C = 10 5.2/1.9 s; chains of 200, 250, 400 unequal
#: bodies, C = 20: 1.3/1.5, 1.5/1.4 s, the kernels 1.13-1.17 times faster at 400; 750 bodies,
#: C = 3 1.90/1.97 s, C = 10 2.77/2.04 s. The kernels break even between 4,500 (300 beams,
#: C = 5) and 9,000 (300 beams, C = 10; 200 beams, C = 20 at 12,000); below, at most 10 %
#: is lost where numpy is chosen above the line (500 beams, C = 3) and a small model's many
#: frequencies (100 beams, C = 40: 12,000) take the kernels 0.3 s too early. A sweep counts
#: its steps (``solves``): ``linmstmm sweep`` of the launcher (34), five modes per step:
#: 25 steps 1.50/2.02 s, 50 steps 2.14/2.40 s, 100 steps 3.51/2.97 s (even near 60 steps,
#: 10,200; the rule takes the kernels from 53).
KERNELS_PAY_FROM = 9000
#: The line for a search that polishes its coarse FE predictions without a Wittrick–Williams
#: counter (a large model: :func:`linmstmm.compiled_model.compiled_system` looks), held
#: against the elements carried one at a time times (the frequencies asked for +
#: PREDICTED_FIXED). Such a search takes 3.5 to 7 evaluations a root, not a scan's 30 to 50,
#: in few batches, and the numpy carry's cost is per batch (each element once per call, for
#: all its frequencies): about 3 + 0.3 C calls for C frequencies. Measured as above
#: (numpy/kernels): cantilevers of 100 beams, C = 40: 1.02/1.30 s; of 300, C = 20, 40:
#: 0.94/1.35, 1.55/1.49 s; of 1,000, C = 5, 10, 20: 1.31/1.42, 1.32/1.41, 2.02/1.62 s; of
#: 2,000, C = 4: 2.67/1.56 s; of 3,000, C = 1, 3: 3.27/1.82, 3.32/1.77 s (there a single
#: frequency costs numpy 0.7 s a call); even near 45,000 (300 beams, C = 40; 1,000, C = 5).
PREDICTED_PAY_FROM = 40000
PREDICTED_FIXED = 10
#: Frequencies a request is taken to ask for where it names no count (a range up to fmax)
#: and its beams' clamped modes do not promise more: the commands' default count.
FREQUENCIES_ASSUMED = 10
#: A beam's weight in that count: the numpy carry's cost of a beam element against a rigid
#: body's or a spring's, taken low (in one process, first 20, 200 elements: a cantilever
#: 2.18 s, a chain of 100 unequal bodies 0.41 s).
BEAM_WEIGHT = 3


def kernels_pay(deduction: Deduction, frequencies: int, solves: int = 1) -> bool:
    """True where loading the compiled kernels costs less than the numpy carry would take:
    the elements carried one at a time (each beam BEAM_WEIGHT times) times the
    ``frequencies`` asked for times the ``solves`` at least KERNELS_PAY_FROM, the runs of a
    repeated cell, which the numpy carry powers, left out (they are looked for only where
    the product reaches that at all), and the kernels compiled on this machine already
    (:func:`kernels_compiled`): a first compilation takes about a minute, more than the
    numpy carry saves on one solve.

    Parameters
    ----------
    deduction : Deduction
        The model's deduction.
    frequencies : int
        Natural frequencies each solve asks for.
    solves : int
        Solves of models of this structure the kernels would serve (a sweep's steps).

    Returns
    -------
    bool
    """
    work = frequencies * solves
    if carried_weight(deduction.topology) * work < KERNELS_PAY_FROM:
        return False
    return carried_alone(deduction) * work >= KERNELS_PAY_FROM and kernels_compiled()


def carried_alone(deduction: Deduction) -> int:
    """The elements ``deduction``'s model carries one at a time (each beam BEAM_WEIGHT
    times) outside runs of a repeated cell, which the numpy carry powers: the weight
    :func:`kernels_pay` holds against KERNELS_PAY_FROM."""
    return carried_weight(deduction.topology) - powered_elements(deduction)  # runs hold no beams


def weight_at_most(model) -> int:
    """An upper bound of :func:`carried_weight` of any topology of ``model``: its elements
    (each beam BEAM_WEIGHT times) and a junction at every point, read off the model alone."""
    return len(model.rigids) + len(model.springs) + BEAM_WEIGHT * len(model.beams) + len(model.points)


def carried_weight(topology) -> int:
    """The elements of ``topology`` (:class:`~linmstmm.topology.Topology`) in the carry
    order, each beam counted BEAM_WEIGHT times: the measure of the numpy carry's work
    that :func:`kernels_pay` holds against KERNELS_PAY_FROM."""
    return sum(BEAM_WEIGHT if topology.elements[e].kind == "beam" else 1 for e in topology.order)


def kernels_compiled() -> bool:
    """Whether numba's cache holds the evaluation kernel for this Python (its index file,
    ``_kernels.evaluate-<line>.py<version>.nbi``, in the package's ``__pycache__`` or under
    NUMBA_CACHE_DIR), without importing numba: a run with the compiled engine leaves it.
    An index written for an older source is taken too (the kernels are then compiled again,
    announced); a cache numba keeps elsewhere is not found, and "auto" then stays on numpy."""
    name = f"_kernels.evaluate-*.py{sys.version_info.major}{sys.version_info.minor}.nbi"
    if any((Path(__file__).parent / "__pycache__").glob(name)):
        return True
    folder = os.environ.get("NUMBA_CACHE_DIR")
    return bool(folder) and any(Path(folder).rglob(name))


#: Transfer elements from which a model may be mostly repeated cells
#: (:func:`repeated_cells_dominate`; fewer: not looked for, a few cells gain nothing).
REPEATED_CELLS_FROM = 200


def repeated_cells_dominate(deduction: Deduction) -> bool:
    """True where runs of a repeated cell (:meth:`Deduction.periodic_runs`) hold more than
    half of at least REPEATED_CELLS_FROM transfer elements: the numpy carry multiplies
    such a run by powers of its cell's matrix, the compiled program element by element
    (a 10,000-body spring chain: 0.5 s by numpy, 16 s compiled)."""
    elements = len(deduction.topology.order)
    if elements < REPEATED_CELLS_FROM:
        return False
    return powered_elements(deduction) > elements / 2


def powered_elements(deduction: Deduction) -> int:
    """The transfer elements of ``deduction`` in runs of a repeated cell, which the numpy
    carry multiplies by powers of the cell's matrix (:meth:`Deduction.periodic_runs`)."""
    return sum(len(run.cell) * run.repetitions for run in deduction.periodic_runs())


class EvaluationCount:
    """Evaluations of det Ū_all (one per frequency) asked for from each thread.

    A compiled model's determinant serves every solve of that model, two at once
    on two threads included; each solve reports the evaluations it took as the
    difference of :attr:`evaluations` over its search, which counts the calling
    thread's only.
    """

    def __init__(self):
        self._counts = threading.local()

    @property
    def evaluations(self) -> int:
        """Evaluations asked for from the calling thread so far."""
        return getattr(self._counts, "total", 0)

    def _count(self, omega) -> None:
        """Count the frequencies of ``omega`` (n,) as evaluations of the calling thread."""
        self._counts.total = self.evaluations + np.size(omega)


class NumpyDeterminant(EvaluationCount):
    """det Ū_all by the numpy carry of ``deduction`` (stable: orthonormalised)."""

    #: The engine this is (:data:`ENGINES`), as results report it.
    engine = "numpy"

    def __init__(self, deduction: Deduction):
        super().__init__()
        self.deduction = deduction

    def log_det(self, omega):
        """(sign or phase (n,), log|det Ū_all| (n,)) at each of ``omega`` (n,) rad/s."""
        omega = np.atleast_1d(omega)
        self._count(omega)
        return self.deduction.log_det(omega)

    def matrix(self, omega):
        """(Ū_all stack (n, N, N), log_scale (n,)), det Ū_all = det(matrix) · exp(log_scale)."""
        omega = np.atleast_1d(omega)
        self._count(omega)
        return self.deduction.matrix(omega, stable=True)

    #: no faster plain Ū_all than the deduction's own, which the probes read themselves
    plain_matrix = None


class CompiledDeterminant(EvaluationCount):
    """det Ū_all of one deduction, evaluated by the compiled kernels.

    The same answers as :meth:`Deduction.log_det` and :meth:`Deduction.matrix`
    with ``stable=True`` (to rounding), without a Python call per element.
    numba is imported, and the kernels compiled or loaded from their cache, on
    the first evaluation.
    """

    #: The engine this is (:data:`ENGINES`), as results report it.
    engine = "compiled"

    def __init__(self, deduction: Deduction):
        super().__init__()
        self.deduction = deduction
        self._released = deduction.released_columns  # the unknowns compiled for
        self.program = compile_program(deduction)
        deduction.adopt_row_kinds(self.program.row_kinds)
        p = self.program
        self._operations = _kernel_operations(p, p.orthos)
        self._layout = (p.workspace, p.slot_rows.size, p.kept_columns.size, p.assembly_sources, p.assembly_targets,
                        p.block_sources, p.block_targets, p.block_offsets, p.block_orders, p.block_sign)

    @property
    def order(self) -> int:
        """Order N of Ū_all (after any release)."""
        return self.program.kept_columns.size

    def _frequencies(self, omega) -> np.ndarray:
        """``omega`` as a contiguous float or complex array (n,), once the program is
        known to serve the deduction's unknowns as they stand."""
        if self.deduction.released_columns is not self._released:
            raise RuntimeError("unknowns were released after this determinant was compiled: compile it anew")
        omega = np.atleast_1d(np.asarray(omega))
        return np.ascontiguousarray(omega.astype(complex if np.iscomplexobj(omega) else float))

    def _evaluate(self, omega, group: int | None, with_matrices: bool):
        omega = self._frequencies(omega)
        self._count(omega)
        return self._replayed(self._operations, omega, group, with_matrices)

    def _replayed(self, operations, omega, group: int | None, with_matrices: bool):
        """(matrices, sign, log_abs, log_scale) of the kernels replaying ``operations``."""
        from linmstmm import _kernels  # numba loads here, not at import

        n, order = omega.size, self.order
        matrices = np.empty((n if with_matrices else 0, order, order), dtype=omega.dtype)  # the kernel writes all
        sign = np.empty(n, dtype=omega.dtype)
        log_abs, log_scale = np.empty(n), np.empty(n)
        if group == 1 and not with_matrices and n > 1:  # each frequency on its own: shared among the cores
            spread(lambda start, stop: _kernels.evaluate(operations, self._layout, omega[start:stop], 1, matrices,
                                                         sign[start:stop], log_abs[start:stop],
                                                         log_scale[start:stop]), n)
        else:
            _kernels.evaluate(operations, self._layout, omega, max(group or n, 1), matrices, sign, log_abs,
                              log_scale)
        return matrices, sign, log_abs, log_scale

    def log_det(self, omega):
        """(sign or phase (n,), log|det Ū_all| (n,)) at each of ``omega`` (n,) rad/s, real or complex.

        Each frequency is evaluated on its own (the determinant does not
        depend on the orthonormalisations chosen), so a batch is shared among
        the cores (:func:`linmstmm.spread.spread`), with the same numbers.
        """
        _, sign, log_abs, _ = self._evaluate(omega, 1, False)
        return sign, log_abs

    def matrix(self, omega):
        """(Ū_all stack (n, N, N), log_scale (n,)): the orthonormalised matrix, with
        det Ū_all = det(matrix) · exp(log_scale). The whole stack takes the same
        decisions, so that differences between its entries are smooth in ω."""
        matrices, _, _, log_scale = self._evaluate(omega, None, True)
        return matrices, log_scale

    def plain_matrix(self, omega) -> np.ndarray:
        """Ū_all (n, N, N) at each of ``omega`` (n,) rad/s, not orthonormalised: the columns
        are the unknowns, :meth:`Deduction.matrix` to rounding; not counted among the
        evaluations.

        The program with every orthonormalisation only laid out (the flag of those the
        final LU takes over, :data:`linmstmm.godunov.FINAL_CARRIES`), one frequency at a
        time. A beam's pieces of βL ≤ 4 are multiplied through, the same transfer as the
        numpy carry's one piece; at the probes of
        :func:`~linmstmm.nullspace.release_indeterminate`, below every beam's own scale,
        each beam is one piece.
        """
        omega = self._frequencies(omega)
        laid_out = self.program.orthos.copy()
        laid_out[:, 4] = 1
        return self._replayed(_kernel_operations(self.program, laid_out), omega, 1, True)[0]


def _kernel_operations(program, orthos: np.ndarray) -> tuple:
    """The arrays of ``program`` that :func:`linmstmm._kernels.evaluate` replays, in its
    order, with ``orthos`` (O, 5) for its orthonormalisation records."""
    p = program
    return (p.slot_offset, p.slot_rows, p.slot_width, p.operations, p.terms, p.places, p.places_start,
            p.matrices, orthos, p.ortho_blocks, p.beams, p.beam_rotation)

