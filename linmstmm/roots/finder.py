"""The coordinating class of the root search (:class:`RootFinder`): its state, its
entry points :meth:`~RootFinder.find` and :meth:`~RootFinder.find_near`, and the
steps it delegates to the modules of :mod:`linmstmm.roots`."""

from __future__ import annotations

import numpy as np

from linmstmm.counting import deflated
from linmstmm.predicted import predicted_roots
from linmstmm.rayleigh import AS_PREDICTED_FROM, PREDICTED_TO, refined_predictions
from linmstmm.roots import brackets, certify, fast_path, floor, pencil, segments, top_count
from linmstmm.roots import clusters as close_roots
from linmstmm.roots.result import RootSearchResult, search_result
from linmstmm.roots.settings import (
    CEILING_RATIO,
    DEFAULT_SCALE,
    FLOOR_RATIO,
    CERTIFIED_STEP,
    MAX_RTOL,
    MAX_XTOL,
    MIN_POINTS_PER_OCTAVE,
    MIN_RTOL,
    POINTS_PER_OCTAVE,
    predictions_wanted,
)


class RootFinder:
    """Finds the natural frequencies of a deduced model.

    log_det : callable omega (n,) -> (sign (n,), log|det| (n,)).
    matrix : callable omega (n,) -> Ū_all stack (n, N, N).
    xtol : Newton's relative tolerance. points_per_octave : scan density, at
    least POINTS_PER_OCTAVE (a denser scan leaves fewer close roots to the
    repairs; a coarser one is refused, see MIN_POINTS_PER_OCTAVE).
    points_per_root : the segment search's scan density per counted root.
    rigid_body_modes : number of zero-frequency modes, from the model's
    kinematics (:func:`linmstmm.rigid_motion.rigid_body_mode_count`); their
    zeros of det Ū_all at ω = 0 are divided out once they are confirmed
    (:meth:`divide_out_rigid_body_zeros`).
    predictor : callable (n, later=False, accuracy=None) -> :class:`~linmstmm.coarse_prediction.PredictedModes`,
    the lowest n elastic roots predicted (rad/s) and their modes at the nodes where
    known, made now or, with ``later``, where the eigensolve can make them afterwards,
    and then to a relative ``accuracy`` where given (by a compiled kernel: given
    only where the counter is compiled, so the numpy engine's answers do not
    depend on what else the process has loaded)
    (:func:`linmstmm.coarse_prediction.predicted_modes` of the model), or None; the
    modes refine the predictions by the Rayleigh functional of the counter's exact
    dynamic stiffness (:func:`linmstmm.rayleigh.refined_predictions`; only of those
    that do not stand as predicted where they may stand unpolished to an rtol from
    :data:`linmstmm.rayleigh.AS_PREDICTED_FROM` up).
    scale : rad/s, the model's own frequency scale; the floor, ceiling and scan
    chunks are multiples of it (see DEFAULT_SCALE).
    rtol : relative accuracy a root is certified to, in [MIN_RTOL, MAX_RTOL]: a root
    whose last step exceeds it is uncertified (the caller refines it in mpmath),
    and the Wittrick–Williams count across each root is made no narrower than it
    (:func:`~linmstmm.roots.certify.near_widths`).
    unpolished : whether a prediction that Wittrick–Williams counts at ±rtol certify
    may be listed as it stands, unpolished (an rtol the caller asked for; from
    :data:`linmstmm.predicted.COUNTED_PREDICTION` up); False, the default, polishes
    every root to xtol.

    Candidates come from the scan; each is polished by local linearisation
    (Newton for the nonlinear eigenproblem Ū(ω) v = 0): with A = Ū(ω) and
    B = dŪ/dω the generalized eigenvalues μ of A v = μ B v are the offsets
    to the nearby roots, ω ← ω − μ. It converges to machine precision for
    simple and for semisimple multiple roots alike (unlike minimising |det|,
    which stalls at √eps for a double root), and a root of multiplicity m
    shows m eigenvalues μ ≈ 0 at convergence.
    """

    #: Offsets |μ|/ω below this are the same root (multiplicity).
    SAME_ROOT = 1e-9
    #: Newton steps |μ|/ω that stop shrinking below this have reached the rounding
    #: floor of Ū_all: the root is accepted, with that step as its uncertainty
    #: (:attr:`last_step`, and the result's ``last_steps``; the caller refines uncertain
    #: roots in mpmath).
    UNCERTAIN = 1e-7
    #: log|det| must rise by this much either side of a root without a sign change (a
    #: double root's rises by 2 ln 10 at ten times the distance to it).
    DIP = 1.0
    #: Offsets |μ|/ω below this may be a multiple root split by rounding (a count decides);
    #: roots closer than this are reported as one multiple root.
    SPLIT = 1e-4
    #: An interval this narrow (relative) that a count says holds roots float64 cannot find
    #: is their enclosure: :meth:`_isolate` reports them at its middle, for
    #: ``natural_frequencies`` to separate in mpmath (:attr:`unseparated`).
    CERTIFIED_WIDTH = 1e-9
    #: A pencil offset |μ|/ω beyond this is past the linearisation's reach: a Newton
    #: step that long is lost, and no partner root is sought there (:func:`pencil.polish`,
    #: ``predicted._partner``); the segment search takes such a start. A varied model's
    #: partner at −3e16 rad/s had the compiled kernels cut its beams into some 1e8
    #: pieces (76 s); the cantilever's double roots had partners 0.17 to 0.48 of ω away
    #: that moved with the units the model was written in (306 evaluations in m, 287
    #: in mm); within 0.1, 249 to 261 in five unit systems.
    NEWTON_REACH = 0.1
    #: Offsets |μ|/ω below this are polished as members of the same cluster.
    CLUSTER_WINDOW = 2e-3
    #: :meth:`_narrowed` evaluates this many − 1 equally spaced points per bracket and round.
    NARROWING_SECTIONS = 8
    #: The same for the fast path's deferred members (:attr:`deferred_members`).
    DEFERRED_WINDOW = 6e-2
    #: A deferred member this close to another root found or start, relative to its
    #: offset from the root that gave it, is that root again (linearisation error).
    MEMBER_OVERLAP = 0.25
    #: Passes of :meth:`_rescanned` over the stored scan, each with the roots the last found.
    RESCANS = 3
    #: After a Newton step below this (relative), the next one is likely the last:
    #: compute all the offsets there, not only the smallest.
    LAST_STEPS = 1e-8
    #: The same where Newton may stop early (:meth:`_quadratic`): one round sooner.
    LAST_STEPS_EARLY = 1e-4
    #: A Newton step below this (relative) that shows quadratic convergence to a
    #: simple root may be the last one (:meth:`_quadratic`).
    EARLY = 1e-9

    def __init__(self, log_det, matrix, xtol: float = 1e-14,
                 points_per_octave: int = POINTS_PER_OCTAVE, points_per_root: int = 6,
                 rigid_body_modes: int = 0, predictor=None, scale: float = DEFAULT_SCALE,
                 rtol: float = CERTIFIED_STEP, unpolished: bool = False):
        if not 0 < xtol <= MAX_XTOL:
            raise ValueError(f"xtol must be in (0, {MAX_XTOL:g}], got {xtol:g}: looser Newton "
                             "tolerances blur distinct roots into one")
        if points_per_octave < MIN_POINTS_PER_OCTAVE:
            raise ValueError(f"points_per_octave must be at least {MIN_POINTS_PER_OCTAVE}, got "
                             f"{points_per_octave:g}: a coarser scan is slower, not faster (the roots "
                             "it misses cost more to recover than it saves; reports/speed_accuracy.md)")
        if not MIN_RTOL <= rtol <= MAX_RTOL:
            raise ValueError(f"rtol must be in [{MIN_RTOL:g}, {MAX_RTOL:g}], got {rtol:g}: roots closer than "
                             f"{self.SPLIT:g} are one multiple root, and digits asks for more than float64's")
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale must be a positive frequency (rad/s), got {scale!r}")
        self.log_det = log_det
        self.matrix = matrix
        #: rad/s: the model's frequency scale, where every count starts, and where a
        #: search for ``count`` roots gives up
        self.scale, self.floor, self.ceiling = scale, FLOOR_RATIO * scale, CEILING_RATIO * scale
        self.xtol = xtol
        #: relative accuracy each root is certified to (see the class docstring)
        self.rtol = rtol
        #: whether a prediction counts certify within rtol may stand unpolished
        self.unpolished = unpolished
        self.points_per_octave = points_per_octave
        self.points_per_root = points_per_root
        #: root -> relative size of the last Newton step that reached it
        self.last_step: dict[float, float] = {}
        #: root -> the pencil's offsets μ (rad/s, complex, by size) seen from it when
        #: Newton reached it (:func:`~linmstmm.roots.pencil.polish`)
        self.offsets_at: dict[float, np.ndarray] = {}
        #: why the search ended early, if it did
        self.note = ""
        self._rigid = rigid_body_modes
        self._divided = False  # the rigid-body zeros divided out of log_det
        #: callable n -> PredictedModes of the lowest elastic roots, or None
        self.predictor = predictor
        #: the compiled determinant behind ``log_det`` and ``matrix``, where the
        #: caller gives one (:mod:`linmstmm.determinant`: it counts evaluations)
        self.determinant = None
        #: starts of cluster members not yet polished (see :meth:`clusters`)
        self.deferred_members: list[tuple[float, float]] = []  # (start, the root whose pencil gave it)
        #: sign-change brackets (lo, hi) Newton missed that :meth:`_needed` left out
        self.left_out: list[tuple[float, float]] = []
        #: rad/s: a count found no root from the floor up to here (see :meth:`_scanned`)
        self.root_free_below = self.floor
        #: root -> (multiplicity, radius rad/s): roots float64 could not tell apart (:meth:`_separated`),
        #: or could not find where a count encloses them (:meth:`_isolate`)
        self.unseparated: dict[float, tuple[int, float]] = {}
        #: root -> multiplicity a circle count gave it (1 where it could not be made; :meth:`_settled`)
        self._counted: dict[float, int] = {}
        #: root -> radius (rad/s) of the circle a count of it was made over (a circle that
        #: reaches out of a segment may hold a root outside it: :meth:`_merge`)
        self._circles: dict[float, float] = {}
        #: (root, radius rad/s) -> natural frequencies within that tight circle about it, or
        #: None where the count could not be made (:meth:`tight_counts`)
        self._tight_counts: dict[tuple[float, float], int | None] = {}
        #: callable omega -> natural frequencies below omega (rad/s), rigid-body modes
        #: included, or None where it cannot decide (a
        #: :class:`~linmstmm.wittrick_williams.ModeCounter`); None: counts by the
        #: argument principle only (see :func:`linmstmm.roots.certify.other_zeros`)
        self.counter = None
        #: for a model too large to count at every root: callable () -> its counter or
        #: None, made only where a stretch must be searched (:meth:`counter_for_stretch`)
        self.late_counter = None

    def divide_out_rigid_body_zeros(self) -> None:
        """Count and scan det Ū_all / ω^2r instead of det Ū_all.

        With r rigid-body modes det ∝ ω^2r at ω = 0: a contour that passes a
        few floors from the origin sees the phase turn 2r times faster
        than ω's own angle, and its sampling aliases (false counts of 2, 4,
        6 roots below the first elastic one). Dividing by ω^2r removes that
        known factor exactly; the roots elsewhere are unchanged. The caller
        has confirmed that the disc |ω| < floor holds exactly 2r zeros
        (:attr:`linmstmm.compiled_model.CompiledSystem.rigid_zeros_confirmed`).
        """
        self.log_det = deflated(self.log_det, np.zeros(self._rigid))
        self._divided = True

    def counter_for_stretch(self):
        """The counter a stretch of roots is searched with (:mod:`~linmstmm.roots.counted_search`):
        :attr:`counter`, made now from :attr:`late_counter` where there is none yet, and
        kept for the rest of the search. A model too large to count at every root
        (:data:`~linmstmm.wittrick_williams.MAX_ORDER`) comes here only where its
        predictions' polish leaves a stretch unsettled: roots closer than det Ū_all and its
        pencil can part, which the counts bisect (each count a factorisation of D(ω),
        10 ms at 690 unknowns, against the hundreds of evaluations of det the
        argument-principle search of such a stretch takes a root). None without either."""
        if self.counter is None and self.late_counter is not None:
            made, self.late_counter = self.late_counter(), None
            self.counter = None if made is None else made.fresh()
        return self.counter

    def rigid_body_modes(self) -> int:
        """Number of zero-frequency (rigid-body) modes, as given at construction."""
        return self._rigid

    @property
    def fine_rtol(self) -> bool:
        """Whether this finder certifies to CERTIFIED_STEP (the default rtol) or finer,
        where its searches of a stretch part a close pair whole inside it; at a looser
        rtol they may keep a pair closer than rtol as one double root
        (:mod:`~linmstmm.roots.counted_search`, :func:`~linmstmm.prediction_groups.repair_split`)."""
        return self.rtol <= CERTIFIED_STEP

    @property
    def same_root(self) -> float:
        """Relative distance within which two polished values are one root: SAME_ROOT,
        or xtol where that is coarser (a loose rtol polishes to rtol/100 only: the
        secant and Newton on the pencil placed one root of a random tree 2e-9 apart
        at rtol 1e-4, and it was taken twice)."""
        return max(self.SAME_ROOT, self.xtol)

    def _existing(self, count: int) -> int | None:
        """How many of ``count`` elastic roots exist below the ceiling where the
        Wittrick–Williams count says fewer do (the model has fewer than ``count``
        modes there); None where it cannot say so."""
        total = self.stiffness_count([], None, self.ceiling)
        return total if total is not None and 0 <= total < count else None

    def find_near(self, guesses, count: int) -> RootSearchResult:
        """The lowest ``count`` roots, warm-started from ``guesses``.

        Guesses (e.g. the roots of a neighbouring scene of the same model) are
        taken as predictions (:func:`~linmstmm.predicted.predicted_roots`: the
        secant on det, one certifying count); where that cannot certify them,
        they are polished on the pencil and one count over (floor, just above
        the count-th root) must confirm that none was missed. Otherwise the
        full search runs.

        Parameters
        ----------
        guesses : array_like, shape (m,)
            rad/s, the roots of a similar model, in any order.
        count : int
            How many of the lowest elastic roots to find.

        Returns
        -------
        RootSearchResult
            The roots (rad/s, ascending, repeated per multiplicity) and the
            search's diagnostics, frozen.
        """
        self.note = ""
        return self._search_result(self._placed_by_counts(self._near(guesses, count)))

    def _near(self, guesses, count: int) -> list[float]:
        """The roots :meth:`find_near` returns, as a list (rad/s)."""
        guesses = np.sort(np.asarray(guesses, dtype=float))
        found = predicted_roots(self, guesses, count) if guesses.size >= count else None
        if found is not None:
            return self._separated_above_floor(found)[:count]
        found = self._confirmed(self._polished(guesses, []), count)
        return found if found is not None else self._search(count, None)

    def find(self, count: int | None, omega_max: float | None) -> RootSearchResult:
        """Elastic roots, ascending, each repeated per multiplicity.

        The lowest ``count``, or all up to ``omega_max``, with none missed:
        from the predictor's frequencies when one count confirms them
        (:func:`~linmstmm.predicted.predicted_roots`, with ``count``), else the
        fast path (:meth:`_scan_ahead`) when one count confirms it, else the
        segment search (:meth:`_search`).

        Parameters
        ----------
        count : int or None
            How many of the lowest elastic roots to find; None: all up to ``omega_max``.
        omega_max : float or None
            rad/s: every root up to it; with ``count``, whichever stops first.

        Returns
        -------
        RootSearchResult
            The roots (rad/s) and the search's diagnostics, frozen: a later
            search on this finder does not change them.
        """
        self.note = ""
        found = self._found(count, omega_max)
        if count is not None and omega_max is None:
            self._check_listed(found, count)
        return self._search_result(self._placed_by_counts(found))

    def _found(self, count: int | None, omega_max: float | None) -> list[float]:
        """The roots :meth:`find` returns, as a list (rad/s)."""
        if count is not None and self.predictor is not None:
            as_predicted = self.unpolished and self.rtol >= AS_PREDICTED_FROM and self.counter is not None
            compiled = as_predicted and getattr(self.counter, "engine", None) == "compiled"
            predicted = self.predictor(predictions_wanted(count), later=as_predicted,
                                       accuracy=PREDICTED_TO * self.rtol if compiled else None)
            wanted = count if predicted.values.size >= count else self._existing(count)
            if wanted == 0:
                return []
            found = None
            if wanted is not None and self._usable(predicted.values):
                predictions, spans = refined_predictions(self.counter, predicted, wanted, self.rtol, as_predicted)
                found = predicted_roots(self, predictions, wanted, spans)
            if found is not None:  # certified up to above the wanted-th: complete below omega_max too
                found = self._separated_above_floor(found)
                return self._cut_at(found[:count], omega_max)
        found = self._scan_ahead(count, omega_max) if count is not None or omega_max is not None else None
        if found is None:
            found = self._search(count, omega_max)
        found = self._separated_above_floor(found)
        return found[:count] if count is not None else found

    #: Evaluations of ``determinant`` already counted in an earlier search's result.
    _evaluations_reported = 0
    #: The frozen result of a search (:mod:`linmstmm.roots.result`).
    _search_result = search_result

    # The steps of the search, each a function of the finder in its own module; called
    # through these attributes, so that one can be timed or replaced on the class.

    # refinement: Newton on the pencil (Ū, dŪ/dω) (:mod:`linmstmm.roots.pencil`)
    _pencil = pencil.pencil
    _offsets = pencil.offsets
    polish = pencil.polish
    _checked = pencil.checked
    _quadratic = pencil.quadratic

    # clusters of close roots and multiplicities (:mod:`linmstmm.roots.clusters`, imported as close_roots)
    clusters = close_roots.clusters
    _multiplicities = close_roots.centre_multiplicities
    cluster = close_roots.cluster
    _recounted = close_roots.recounted
    _as_counted = close_roots.as_counted
    _circle_radius = close_roots.circle_radius
    multiplicities = close_roots.multiplicities
    tight_counts = close_roots.tight_counts
    beside = close_roots.beside
    offsets_of = close_roots.offsets_of
    unseparated_among = close_roots.unseparated_among
    multiplicity = close_roots.multiplicity
    _separated = close_roots.separated

    # the floor: nothing hides below it (:mod:`linmstmm.roots.floor`)
    _separated_above_floor = floor.separated_above_floor
    _usable = floor.usable
    _check_floor = floor.check_floor

    # sign-change brackets and the roots Newton reaches from them (:mod:`linmstmm.roots.brackets`)
    shrink_brackets = brackets.shrink_brackets
    _narrowed = brackets.narrowed
    _bracketed = brackets.bracketed
    _narrowed_groups = brackets.narrowed_groups
    _needed = brackets.needed
    _bracket_roots = brackets.bracket_roots
    _merge = brackets.merge
    _polished = brackets.polished
    _with_groups = brackets.with_groups

    # the segment search: count, scan, bisect (:mod:`linmstmm.roots.segments`)
    _roots_in = segments.roots_in
    _split_point = segments.split_point
    _isolate = segments.isolate
    segment = segments.segment
    _lowest = segments.lowest
    _next_top = staticmethod(segments.next_top)
    _search = segments.search

    # the list at its end against the count at its top (:mod:`linmstmm.roots.top_count`)
    _check_listed = top_count.check_listed

    # certification by counts: Wittrick–Williams, else the argument principle (:mod:`linmstmm.roots.certify`)
    _confirmed = certify.confirmed
    _settled = certify.settled
    _count_top = certify.count_top
    _recovered = certify.recovered
    _below_count = staticmethod(certify.below_count)
    _cut_at = certify.cut_at
    confirm_no_other_zeros = certify.confirm_no_other_zeros
    other_zeros = certify.other_zeros
    stiffness_count = certify.stiffness_count
    stiffness_other_zeros = certify.stiffness_other_zeros
    counted_multiplicities = certify.counted_multiplicities
    _placed_by_counts = certify.placed_by_counts

    # the fast path: scan ahead, polish, close by one count (:mod:`linmstmm.roots.fast_path`)
    _scan_ahead = fast_path.scan_ahead
    _closed = fast_path.closed
    _with_members = fast_path.with_members
    _with_left_out = fast_path.with_left_out
    _member_starts = fast_path.member_starts
    _rescanned = fast_path.rescanned
    _deflated_candidates = fast_path.deflated_candidates
    _scanned = fast_path.scanned
    _holds_no_roots = fast_path.holds_no_roots
    _quick_grid = fast_path.quick_grid
