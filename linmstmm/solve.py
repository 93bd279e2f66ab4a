"""Natural frequencies of a model: topology → deduction → roots → result."""
from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field, replace

import numpy as np

from linmstmm.coarse_prediction import predicted_modes
from linmstmm.compiled_model import compiled_system
from linmstmm.deduction import Deduction
from linmstmm.determinant import FREQUENCIES_ASSUMED
from linmstmm.mode_bound import check_range_request, clamped_modes_below
from linmstmm.model import Model
from linmstmm.results import Result, decode_array
from linmstmm.roots import CERTIFIED_STEP, MAX_XTOL, RootFinder, RootSearchResult, SearchAtDefaultRtol
from linmstmm.stages import report
from linmstmm.threads import single_blas_thread
from linmstmm.wording import counted

#: Digits float64 delivers; more are computed in mpmath.
FLOAT64_DIGITS = 14
#: Digits used when an uncertified root is escalated to mpmath.
ESCALATION_DIGITS = 20
#: With ``rtol``, the secant and Newton polish stop at steps this fraction of it
#: (within float64's reach, and no looser than MAX_XTOL): a superlinear step that
#: small leaves an error far below rtol, which the count across the root confirms.
XTOL_PER_RTOL = 1e-2
#: The engine a result loaded from a file saved before results recorded theirs reports.
UNRECORDED_ENGINE = "unrecorded"


@dataclass(frozen=True)
class FrequencyResult(Result):
    """Elastic natural frequencies (Hz, ascending, repeated per multiplicity).

    rigid_body_modes : number of zero-frequency modes. ubar_order : order of
    Ū_all as deduced. indeterminate_released : statically indeterminate
    unknowns (redundant rigid constraints) released before the root search.
    seconds : wall time of the solve (loading excluded).
    precision : "float64", or "mpmath:<digits>" when roots were refined in
    mpmath (all of them for ``digits`` > 15, else only those float64 could
    not certify). frequencies_text, omegas_text : the frequencies (Hz) and
    circular frequencies (rad/s) as decimal strings at that precision (mpmath only).
    evaluations : float64 evaluations of det Ū_all (one per frequency) the
    search and its certifying counts took.
    engine : "numpy" or "compiled": what evaluated det Ū_all in float64 ("auto"
    resolved; :func:`linmstmm.determinant.determinant`); UNRECORDED_ENGINE for a
    result saved before results recorded it.
    """

    model: str
    frequencies_hz: np.ndarray
    rigid_body_modes: int
    ubar_order: int
    seconds: float
    precision: str = "float64"
    note: str = ""
    indeterminate_released: int = 0
    frequencies_text: list | None = None
    omegas_text: list | None = None
    evaluations: int = 0
    engine: str = "numpy"

    kind = "freqs"

    def to_dict(self) -> dict:
        """The ``linmstmm freqs --json`` object (``docs/cli.md``).

        Returns
        -------
        dict
            JSON-ready: ``model``, ``frequencies_hz``, ``rigid_body_modes``, ``ubar_order``,
            ``seconds``, ``precision``, ``method``, ``indeterminate_released``, ``evaluations``,
            ``engine`` and, when set, ``note``, ``frequencies_hz_text``, ``omega_rad_s_text``.
        """
        return {
            "model": self.model,
            "frequencies_hz": [float(f) for f in self.frequencies_hz],
            "rigid_body_modes": int(self.rigid_body_modes),
            "ubar_order": int(self.ubar_order),
            "seconds": float(self.seconds),
            "precision": self.precision,
            "method": "mstmm",
            "indeterminate_released": int(self.indeterminate_released),
            "evaluations": int(self.evaluations),
            "engine": self.engine,
            **({"note": self.note} if self.note else {}),
            **({"frequencies_hz_text": self.frequencies_text} if self.frequencies_text else {}),
            **({"omega_rad_s_text": self.omegas_text} if self.omegas_text else {}),
        }

    @classmethod
    def _from_data(cls, data: dict) -> FrequencyResult:
        """The result :meth:`to_dict` describes (which holds all of it)."""
        return cls(data["model"], decode_array(data["frequencies_hz"]), data["rigid_body_modes"],
                   data["ubar_order"], data["seconds"], data["precision"], data.get("note", ""),
                   data["indeterminate_released"], data.get("frequencies_hz_text"), data.get("omega_rad_s_text"),
                   data["evaluations"], data.get("engine", UNRECORDED_ENGINE))

    def plot(self):
        """Draw the frequencies against their mode number.

        Returns
        -------
        matplotlib.figure.Figure
            :func:`linmstmm.plot.frequency_figure`, titled by the model and method; unsaved.
        """
        from linmstmm.plot import frequency_figure

        title = f"{self.model}: natural frequencies (transfer matrix method)"
        return frequency_figure(self.frequencies_hz, self.rigid_body_modes, title=title)


def frequency_finder(model: Model, root: str | None = None, cut_at=(), engine: str = "auto",
                     frequencies: int = FREQUENCIES_ASSUMED, predicted: bool = False, **options):
    """The deduced system of ``model`` and a new root finder on its stable determinant.

    The system is compiled once per model object (:func:`~linmstmm.compiled_model.compiled_system`:
    deduction, program, released unknowns, rigid-body modes, the counter's
    matrices); the finder is new, and so is everything it finds.
    engine : how det Ū_all is evaluated, "auto", "numpy" or "compiled"
    (:func:`linmstmm.determinant.determinant`; kept as ``finder.determinant``
    with its count of evaluations); the deduction's own numpy carry serves
    mode shapes and the mpmath refinement either way.
    frequencies, predicted : how many the search is to find, and whether it is for the lowest
    that many from the coarse predictions (for "auto", :func:`~linmstmm.compiled_model.compiled_system`).
    root, cut_at : see :func:`linmstmm.topology.build_topology`. options go to
    :class:`linmstmm.roots.RootFinder` (xtol, points_per_octave, points_per_root, rtol).
    The finder knows the rigid-body modes (counted from the model's kinematics)
    and, where the disc of its floor holds exactly their zeros, divides those
    out of det Ū_all (:meth:`~linmstmm.roots.RootFinder.divide_out_rigid_body_zeros`),
    so every caller's counts see the elastic roots only. Its closing counts are
    Wittrick–Williams counts where they can decide
    (:class:`~linmstmm.wittrick_williams.ModeCounter`, by the same engine, for
    models small enough: :func:`~linmstmm.wittrick_williams.mode_counter`). Its frequency scale (floor,
    ceiling, scan chunks) is the lowest of the model's
    :func:`~linmstmm.nullspace.characteristic_frequencies`, so that no decision
    depends on the units the model is written in.
    Returns (deduction, finder, number of indeterminate unknowns released).
    """
    system = compiled_system(model, root, cut_at, engine, frequencies, predicted)
    evaluator = system.determinant
    finder = RootFinder(evaluator.log_det, lambda omega: evaluator.matrix(omega)[0],
                        rigid_body_modes=system.rigid_body_modes,
                        predictor=functools.partial(predicted_modes, model), scale=system.scale, **options)
    finder.determinant = evaluator
    finder._evaluations_reported = evaluator.evaluations  # this finder's search counts from here
    if system.counter is not None:
        finder.counter = system.counter.fresh()
    finder.late_counter = system.late_counter
    if system.rigid_zeros_confirmed:
        finder.divide_out_rigid_body_zeros()
    return system.deduction, finder, system.released


def search_up_to(finder: RootFinder, count: int | None, fmax: float) -> RootSearchResult:
    """The finder's search for the lowest ``count`` roots (None: all) up to ``fmax`` Hz.

    A root within the accuracy its value is certified to (the finder's
    ``rtol``) above ``fmax`` cannot be told from one on it, so it is listed
    as one: the search's ceiling is 2π fmax (1 + rtol). A ceiling on a root
    stops the search (the count of the roots below it cannot be made); a
    root is then on 2π fmax (1 + rtol) to rounding, so the search is made
    once more with its ceiling half ``rtol`` higher, where that root is
    listed.

    Parameters
    ----------
    finder : RootFinder
        The finder of the search.
    count : int or None
        The lowest ``count`` roots; None: every root up to the ceiling.
    fmax : float
        Hz, the frequency asked for.

    Returns
    -------
    RootSearchResult
    """
    try:
        return finder.find(count, 2 * np.pi * fmax * (1 + finder.rtol))
    except RuntimeError:  # a root on the ceiling; any other failure recurs and is raised
        return finder.find(count, 2 * np.pi * fmax * (1 + 1.5 * finder.rtol))


@dataclass(frozen=True, eq=False)
class RootSolution:
    """The roots of det Ū_all a request asked for, and the system they belong to.

    Attributes
    ----------
    deduction : Deduction
        The deduced system (Ū_all and the states behind it).
    finder : RootFinder
        The root finder that found them, for work after the search (its
        determinant, the multiplicity of a root cut by the count).
    search : RootSearchResult
        What its search returned: the roots in float64 and the search's
        diagnostics (rigid-body modes, note, ceiling).
    released : int
        Statically indeterminate unknowns released before the search.
    omegas : numpy.ndarray, shape (n,)
        Elastic natural frequencies, rad/s, ascending, repeated per multiplicity.
    precision : str
        "float64", or "mpmath:<digits>" when roots were refined in mpmath.
    frequencies_text, omegas_text : list of str or None
        With mpmath: the frequencies (Hz) and circular frequencies (rad/s) as decimal strings.
    unseparated : dict
        Root (rad/s) -> (multiplicity, radius rad/s) of each cluster neither
        float64 nor mpmath could separate.
    evaluations : int
        Float64 evaluations of det Ū_all the search and the mpmath refinement took.
    fallback : str
        Where a search at an rtol finer than the default could not be certified, or its
        roots not refined in mpmath, and the default search's roots stand instead: why,
        and that they are certified to the default rtol only ("" otherwise).
    """

    deduction: Deduction
    finder: RootFinder
    search: RootSearchResult
    released: int
    omegas: np.ndarray
    precision: str = "float64"
    frequencies_text: list | None = None
    omegas_text: list | None = None
    unseparated: dict = field(default_factory=dict)
    evaluations: int = 0
    fallback: str = ""


def solve_roots(model: Model, count: int | None = 10, fmax: float | None = None, *, digits: int | None = None,
                root: str | None = None, guess_hz=None, engine: str = "auto",
                rtol: float | None = None) -> RootSolution:
    """The elastic roots of det Ū_all of ``model``: the one pipeline of frequencies and modes.

    Builds the deduction and its root finder (:func:`frequency_finder`), finds
    the roots asked for and refines in mpmath what float64 cannot certify.

    Parameters
    ----------
    model : Model
        The model.
    count : int or None
        The lowest ``count`` roots; None: every root up to ``fmax``.
    fmax : float or None
        Hz: every root up to fmax; with ``count``, whichever stops first.
    digits : int or None
        Significant digits wanted; above FLOAT64_DIGITS every root is refined
        in mpmath. Without it, roots float64 cannot certify are refined at
        ESCALATION_DIGITS, and so are clusters float64 could not tell apart
        (:func:`~linmstmm.precision.separated_cluster`).
    root : str or None
        Boundary end (point name) to use as the root of the transfer tree.
    guess_hz : array_like or None
        Frequencies of a similar model to start from (with ``count`` only).
    engine : str
        How det Ū_all is evaluated: "numpy", "compiled" or "auto".
    rtol : float or None
        Relative accuracy every root is certified to (:func:`natural_frequencies`).

    Returns
    -------
    RootSolution

    Raises
    ------
    ModelError
        For ``fmax`` alone that is not finite, or below which the beams have
        more modes than a range is searched for (:func:`~linmstmm.mode_bound.check_range_request`).
    """
    if fmax is not None and count is None:
        check_range_request(model, fmax)
    report("deducing Ubar_all")
    accuracy = {} if rtol is None else {"rtol": rtol, "xtol": min(max(XTOL_PER_RTOL * rtol, 1e-14), MAX_XTOL),
                                        "unpolished": True}
    frequencies = count if count is not None else max(clamped_modes_below(model, 2 * np.pi * fmax),
                                                      FREQUENCIES_ASSUMED)  # a range: at least its clamped modes
    predicted = count is not None and guess_hz is None  # (else a scan, or a search from the guesses)
    deduction, finder, released = frequency_finder(model, root, engine=engine, frequencies=frequencies,
                                                   predicted=predicted, **accuracy)
    report("finding roots")
    loose = rtol is not None and rtol > CERTIFIED_STEP
    try:
        search = _searched(finder, count, fmax, guess_hz)
    except (RuntimeError, SearchAtDefaultRtol) as error:
        if rtol is None or rtol == CERTIFIED_STEP:
            raise
        if not loose:  # (an octahedral star, planes 1e-6 apart, at rtol 1e-12: the count at its top caught it)
            return _at_default_rtol(model, count, fmax, root, guess_hz, engine,
                                    finder.determinant.evaluations - finder._evaluations_reported,
                                    f"the search at rtol {rtol:g} could not be certified ({error})")
        search = None
    abandoned = 0  # evaluations of a search made again at the default accuracy
    if loose and (search is None or search.unseparated or _uncertain(search, finder.rtol)):
        # A looser rtol asks for less work, not for an answer that cannot be certified, nor
        # for more: where the search at it cannot certify (a varied test model with
        # stiffnesses 4e10 apart at rtol 1e-4: two secant values at extrema of det, 4e-4
        # from their roots, then no count by the argument principle), reaches a stretch
        # its counts cannot search (SearchAtDefaultRtol), or leaves roots to mpmath (an
        # octahedral star, one beam an arm, whose cluster members lie 1e-7 apart at rtol
        # 1e-7: a 4-fold root that did not settle in mpmath, where the default rtol parts
        # them in float64 in 0.7 s), the search is made again at the default accuracy,
        # and what that leaves goes to mpmath.
        report("searching again at the default accuracy")
        abandoned = finder.determinant.evaluations - finder._evaluations_reported if search is None \
            else search.evaluations
        deduction, finder, released = frequency_finder(model, root, engine=engine, frequencies=frequencies,
                                                       predicted=predicted)
        search = _searched(finder, count, fmax, guess_hz)
    omegas, unseparated = search.roots, dict(search.unseparated)
    uncertain = _uncertain(search, finder.rtol if rtol is None else rtol)
    every = bool(digits and digits > FLOAT64_DIGITS)
    wanted = digits if every else (ESCALATION_DIGITS if uncertain or unseparated else None)
    if not wanted:
        return RootSolution(deduction, finder, search, released, omegas, unseparated=unseparated,
                            evaluations=abandoned + search.evaluations)
    report(f"refining in mpmath to {wanted} digits")
    before = finder.determinant.evaluations
    try:
        omegas, precision, text, omega_text = _refined_in_mpmath(
            deduction, model, finder, omegas, [w for w in omegas if w not in unseparated and (every or w in uncertain)],
            unseparated, wanted, cut_by_count=count is not None)
    except RuntimeError as error:  # (a cluster of double roots 1e-7 apart at rtol 1e-12)
        if rtol is None or rtol >= CERTIFIED_STEP:
            raise
        return _at_default_rtol(model, count, fmax, root, guess_hz, engine,
                                abandoned + search.evaluations + finder.determinant.evaluations - before,
                                f"the roots at rtol {rtol:g} could not be refined in mpmath ({error})")
    return RootSolution(deduction, finder, search, released, omegas, precision, text, omega_text, unseparated,
                        abandoned + search.evaluations + finder.determinant.evaluations - before)


def _at_default_rtol(model: Model, count, fmax, root, guess_hz, engine: str, spent: int, why: str) -> RootSolution:
    """:func:`solve_roots` at the default rtol, where a solve at a finer rtol could not be
    certified (``why``) after ``spent`` evaluations of det: its roots, with a
    :attr:`RootSolution.fallback` that says they are certified to the default rtol only.
    The default search may list a pair 5e-11 apart as one double value, which rtol 1e-12
    would part: an octahedral star came back 52 rtol off at rtol 1e-12 where its roots
    were refined in mpmath without saying so."""
    report("searching again at the default accuracy")
    solution = solve_roots(model, count, fmax, root=root, guess_hz=guess_hz, engine=engine)
    return replace(solution, evaluations=spent + solution.evaluations,
                   fallback=f"{why}: these frequencies are certified to the default rtol {CERTIFIED_STEP:g} only")


def _uncertain(search: RootSearchResult, rtol: float) -> list[float]:
    """The roots (rad/s, ascending, distinct) of ``search`` float64 could not certify to
    ``rtol`` (a last Newton step above it), but for those it could not part (its
    ``unseparated``: a root no Newton step reached has a NaN step and is among them)."""
    return sorted({w for w, step in search.last_steps.items() if step > rtol} - set(search.unseparated))


def _searched(finder: RootFinder, count: int | None, fmax: float | None, guess_hz) -> RootSearchResult:
    """The roots of :func:`solve_roots` (arguments as there) found by ``finder``."""
    if fmax is not None:
        return search_up_to(finder, count, fmax)
    if guess_hz is not None and count is not None:
        return finder.find_near(2 * np.pi * np.asarray(guess_hz, dtype=float), count)
    return finder.find(count, None)


@single_blas_thread
def natural_frequencies(model: Model, count: int | None = 10, fmax: float | None = None,
                        digits: int | None = None, root: str | None = None,
                        guess_hz=None, engine: str = "auto", rtol: float | None = None) -> FrequencyResult:
    """Elastic natural frequencies of ``model`` by the transfer matrix method.

    Parameters
    ----------
    model : Model
        The model.
    count : int or None
        The lowest N; None: every frequency up to ``fmax``.
    fmax : float or None
        Hz: all up to fmax; with ``count``, whichever stops first. A root
        within ``rtol`` above fmax counts as on it and is listed
        (:func:`search_up_to`).
    digits : int or None
        Significant digits wanted; above FLOAT64_DIGITS every root is
        refined in mpmath. Without it, roots float64 cannot certify are
        refined at ESCALATION_DIGITS automatically, and so are clusters of
        roots float64 could not tell apart (:attr:`RootSearchResult.unseparated`,
        separated by :func:`~linmstmm.precision.separated_cluster`); a
        cluster mpmath cannot separate either is named in the note.
    root : str or None
        Boundary end (point name) to use as the root of the transfer tree.
    guess_hz : array_like or None
        Frequencies of a similar model (a neighbouring scene) to start from;
        used with ``count`` only, and checked by a root count either way.
    engine : str
        How det Ū_all is evaluated: "numpy", "compiled" (numba), or "auto"
        (compiled where the kernels are already loaded in this process, or where
        the model's elements times ``count`` make the numpy carry slower than
        loading them, :func:`linmstmm.determinant.kernels_pay`, later where a large
        model's search polishes its predictions without a counter,
        :func:`linmstmm.compiled_model.compiled_system`; see :mod:`linmstmm.determinant`).
        The roots agree to rounding either way, and ``result.engine`` says which ran.
    rtol : float or None
        Relative accuracy every frequency is certified to, MIN_RTOL to MAX_RTOL
        (1e-12 to 1e-4). None: certified to 1e-9 and every root polished to rounding.
        Given, from 1e-9 up, a lone prediction (its Rayleigh refinement where it has
        one) that the count across it certifies is listed unpolished, within rtol of
        its root (:func:`~linmstmm.predicted.predicted_roots`): rtol=1e-9 certifies
        what the default does, in fewer evaluations, to 1e-9 rather than to rounding.

    Returns
    -------
    FrequencyResult

    Raises
    ------
    ModelError
        For ``fmax`` alone that is not finite, or below which the beams have
        more modes than a range is searched for
        (:func:`~linmstmm.mode_bound.check_range_request`).
    ValueError
        For ``rtol`` outside its range, or given with ``digits``.
    """
    if rtol is not None and digits is not None:
        raise ValueError("give rtol or digits, not both: digits asks for mpmath's precision, rtol for float64's")
    start = time.perf_counter()
    solution = solve_roots(model, count, fmax, digits=digits, root=root, guess_hz=guess_hz, engine=engine,
                           rtol=rtol)
    search, omegas = solution.search, solution.omegas
    note = search_note(search, omegas.size, solution.unseparated, count, fmax, solution.fallback)
    return FrequencyResult(model.name, omegas / (2 * np.pi), search.rigid_body_modes,
                           solution.deduction.full_order, time.perf_counter() - start,
                           precision=solution.precision, note=note, indeterminate_released=solution.released,
                           frequencies_text=solution.frequencies_text, omegas_text=solution.omegas_text,
                           evaluations=solution.evaluations, engine=solution.finder.determinant.engine)


def search_note(search: RootSearchResult, found: int, unseparated, count: int | None, fmax: float | None,
                fallback: str = "") -> str:
    """What a result of ``found`` elastic roots, asked for by ``count`` and/or ``fmax``,
    must say about the ``search`` that found them ("" if nothing): each cluster float64
    could not separate (``unseparated``: root rad/s -> (multiplicity, radius rad/s)), a
    search that stopped short of what was asked (:attr:`RootSearchResult.note`), that
    fewer than ``count`` exist (below :attr:`RootSearchResult.ceiling`), and the
    ``fallback`` of :class:`RootSolution` (a finer rtol not certified)."""
    notes = [(f"float64 could not tell {m} roots within ±{radius / (2 * np.pi):.3g} Hz of {w / (2 * np.pi):.10g} Hz "
              "apart (a cluster, or a multiple root it could not confirm): they are reported together there")
             if m > 1 else
             (f"float64 could not locate the root a count encloses within ±{radius / (2 * np.pi):.3g} Hz of "
              f"{w / (2 * np.pi):.10g} Hz: it is reported there")
             for w, (m, radius) in unseparated.items()]
    fewer = count is not None and found < count
    if search.note and (fewer or count is None):  # the search stopped short of what was asked
        notes.append(f"only {counted(found, 'elastic natural frequency was', 'elastic natural frequencies were')} "
                     f"found: {search.note}")
    elif fewer and fmax is None:
        notes.append(f"only {counted(found, 'elastic natural frequency exists', 'elastic natural frequencies exist')} "
                     f"below {search.ceiling:.3g} rad/s")
    return "; ".join(notes + [fallback] if fallback else notes)


def _refined_in_mpmath(deduction, model, finder, omegas, chosen, unseparated, digits, cut_by_count):
    """The roots ``chosen`` (rad/s, of ``omegas``) refined in mpmath to ``digits`` and the
    clusters in ``unseparated`` separated there (each one separated leaves it).

    The last root may be one of several equal ones cut off by the count
    (``cut_by_count``): its multiplicity, as a circle counted it, goes to the refinement.
    Returns (omegas (n,) float, precision label, frequency texts (Hz), omega texts (rad/s)):
    the texts at ``digits`` where refined, float reprs elsewhere.
    """
    import mpmath  # here, with the refinement: a float64 solve starts without mpmath

    from linmstmm.precision import refine_roots, separated_cluster

    top = [omegas[-1]] if cut_by_count and len(chosen) and max(chosen) == omegas[-1] else []
    cut = {w: finder.multiplicity(w, sorted(set(omegas))) for w in top}
    refined = {}  # root -> its refined values in order (a cluster's members differ)
    for w, value in zip(chosen, refine_roots(deduction, model, list(chosen), digits,
                                             {w: m for w, m in cut.items() if m},
                                             log_det=finder.determinant.log_det)):
        refined.setdefault(w, []).append(value)
    values = [refined[w].pop(0) if refined.get(w) else None for w in omegas]
    distinct_refined = len(set(chosen))
    for w, (m, radius) in list(unseparated.items()):
        members = separated_cluster(deduction, model, w, m, radius, digits)
        if members is not None:
            for i, member in zip([i for i, x in enumerate(omegas) if x == w], members):
                values[i] = member
            distinct_refined += len(set(members))
            del unseparated[w]
    with mpmath.workdps(digits + 10):  # 2π and the division at the refined precision
        text = [mpmath.nstr(v / (2 * mpmath.pi), digits) if v is not None else repr(float(w / (2 * np.pi)))
                for w, v in zip(omegas, values)]
        omega_text = [mpmath.nstr(v, digits) if v is not None else repr(float(w)) for w, v in zip(omegas, values)]
    omegas = np.array([float(v) if v is not None else w for w, v in zip(omegas, values)])
    precision = f"mpmath:{digits}" + ("" if all(v is not None for v in values) else f" ({distinct_refined} roots)")
    return omegas, precision, text, omega_text
