"""Roots of det Ū_all(ω): count, scan, bracket, refine, multiplicity.

Nothing is missed because every root found is checked against a count by
the argument principle (:mod:`linmstmm.counting`).

The fast path (:meth:`RootFinder._scan_ahead`) scans (sign, log|det|)
upwards until it has seen enough candidates, polishes them all at once and
keeps the result only if one count from the floor agrees: the count of
det with the found roots divided out (:func:`~linmstmm.counting.deflated`)
must be zero, which a missed root or a false one would break. Where it is
not, the missing roots are looked for in the stored scan and by deflated
counts (:meth:`RootFinder._closed`); failing that, the search works
segment by segment upwards:

1. a count, then a scan on a geometric grid of at least ``points_per_root``
   points per counted root;
2. Newton starts where the line through |det| crosses zero in each sign
   change, and at local minima of log|det| without a sign change (even
   multiplicity, close pairs);
3. Newton on the local linearisation (:meth:`RootFinder.polish`, all starts
   at once) converges to machine precision on simple and semisimple multiple
   roots alike; the multiplicity comes from the linearised pencil's
   near-zero offsets, confirmed by a count over a small circle;
4. bisection on the count finds whatever the scan missed, or raises an
   honest error if float64 cannot separate the roots.

Everything works on (sign, log|det|), so nothing overflows; the evaluation
itself is the stable (orthonormalised) one of :mod:`linmstmm.deduction`.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from linmstmm.counting import count_in_disc, count_zeros, count_zeros_many, deflated, divided_out
from linmstmm.nullspace import equilibration
from linmstmm.predicted import predicted_roots

#: Grid points per octave of the scans (the fast path's above FINE_SCAN_RATIO × scale, an
#: eighth of it below; every segment's).
POINTS_PER_OCTAVE = 24
#: Coarser scans are refused. They were never faster: a coarse scan leaves
#: roots that the closing count finds missing, and the repairs cost more than
#: the scan saved. Measured on this machine before they were refused: MLRS 10 modes
#: 39 ms at 16, 52 ms at 12, 0.3–0.5 s at 4 and 2; the tip-mass cantilever
#: 40 modes 78 ms at 24, 158 ms at 20, 172 ms at 16; a 1000-beam chain
#: 3.3 s at 24, 6.6 s at 16; a 10,000-body spring chain 1.0–1.2 s at all.
MIN_POINTS_PER_OCTAVE = POINTS_PER_OCTAVE
#: A root whose last Newton step (its rounding floor in float64) was larger than this,
#: relative, is uncertified: checked on det itself (:meth:`RootFinder._checked`), and
#: refined in mpmath by ``natural_frequencies``.
CERTIFIED_STEP = 1e-9
#: Loosest Newton tolerance (relative) RootFinder accepts: roots are told apart
#: down to SPLIT = 1e-4, so the polishing must be much tighter than that.
MAX_XTOL = 1e-6
#: Widest segment scanned in one grid, octaves (wider ones are split by a count).
SCAN_OCTAVES = 4
#: Every frequency the search decides by is a multiple of the model's own frequency
#: scale (:attr:`RootFinder.scale`, rad/s; :func:`linmstmm.solve.frequency_finder` takes
#: the lowest of :func:`linmstmm.nullspace.characteristic_frequencies`), so a model
#: written in mm or km, or a slow one, is searched alike. A scale of DEFAULT_SCALE
#: gives the absolute values (rad/s) the search was tuned with: floor 1e-3, first
#: chunk 8, fine scan from 1, first segment 2π, ceiling 1e9.
DEFAULT_SCALE = 10.0
#: Lowest scanned circular frequency (:attr:`RootFinder.floor`), times the scale.
FLOOR_RATIO = 1e-4
#: Top of the fast path's first chunk, times the scale.
FIRST_CHUNK_RATIO = 0.8
#: The fast path's scan takes points_per_octave above this (times the scale), an eighth below.
FINE_SCAN_RATIO = 0.1
#: Top of the segment search's first segment, times the scale.
FIRST_SEGMENT_RATIO = 2 * np.pi / DEFAULT_SCALE
#: The scan for ``count`` roots gives up above this (:attr:`RootFinder.ceiling`), times the scale.
CEILING_RATIO = 1e8
#: Where the lowest root found is below this many times the floor, a count in the disc
#: of the floor's radius checks that no elastic root hides below it (:meth:`RootFinder._check_floor`).
FLOOR_CHECK = 1e3
#: Predictions asked for beyond the count (plus a tenth of it): a coarse mesh can rank
#: a true root among the first N one or two places too high (the launcher's 100th).
PREDICTION_MARGIN = 2
#: Predictions whose lowest is below this many times the floor are not used (the scan
#: from the floor searches instead): with an absolute floor of 1e-3 rad/s a free strip
#: 9.9 m long with Iz = 1e-12 m⁴ (first bending mode 1.4e-3 rad/s) was refused; the
#: floor now follows the beam's own scale and it is found.
FLOOR_MARGIN = 5.0
#: Starting points of a half-ellipse count with the known roots divided out.
DEFLATED_POINTS = 9
#: Starting points of a count over a small circle (a multiplicity).
CIRCLE_POINTS = 9
#: Points a count over a small circle may take before it fails. One root of
#: multiplicity m turns the phase by mπ; the test suite's circles (NAFEMS FV2's
#: sevenfold roots among them) took at most 41. Around "roots" Newton settled on
#: where det is rounding noise they refine until this: random ring 5 up to 1e9 Hz,
#: 125 circles in one count, ran out of memory at 117,000 points a round with the
#: general limit.
CIRCLE_MAX_POINTS = 200
#: Points a count with the known roots divided out may take before it fails. Such a
#: phase hardly turns: the fast path's took at most 423 on 40 random models at 80 modes
#: (before each point carried its derivative, at twice the evaluations: half as many now).
#: One that did not settle took 20,000 (the limit then) twice over, and random
#: floating_loops 70 at 80 modes spent 100 s on it before the segment search found
#: all 80 in 2 s.
DEFLATED_MAX_POINTS = 1000


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
    predictor : callable n -> (m,) rad/s, the lowest n elastic roots predicted
    (e.g. :func:`linmstmm.predicted.predict_frequencies` of the model), or None.
    scale : rad/s, the model's own frequency scale; the floor, ceiling and scan
    chunks are multiples of it (see DEFAULT_SCALE).

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
    #: (:attr:`last_step`; the caller refines uncertain roots in mpmath).
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
                 rigid_body_modes: int = 0, predictor=None, scale: float = DEFAULT_SCALE):
        if not 0 < xtol <= MAX_XTOL:
            raise ValueError(f"xtol must be in (0, {MAX_XTOL:g}], got {xtol:g}: looser Newton "
                             "tolerances blur distinct roots into one")
        if points_per_octave < MIN_POINTS_PER_OCTAVE:
            raise ValueError(f"points_per_octave must be at least {MIN_POINTS_PER_OCTAVE}, got "
                             f"{points_per_octave:g}: a coarser scan is slower, not faster (the roots "
                             "it misses cost more to recover than it saves; reports/speed_accuracy.md)")
        if not (np.isfinite(scale) and scale > 0):
            raise ValueError(f"scale must be a positive frequency (rad/s), got {scale!r}")
        self.log_det = log_det
        self.matrix = matrix
        #: rad/s: the model's frequency scale, where every count starts, and where a
        #: search for ``count`` roots gives up
        self.scale, self.floor, self.ceiling = scale, FLOOR_RATIO * scale, CEILING_RATIO * scale
        self.xtol = xtol
        self.points_per_octave = points_per_octave
        self.points_per_root = points_per_root
        #: root -> relative size of the last Newton step that reached it
        self.last_step: dict[float, float] = {}
        #: why the search ended early, if it did
        self.note = ""
        self._rigid = rigid_body_modes
        self._divided = False  # the rigid-body zeros divided out of log_det
        #: callable n -> (m,) predicted lowest elastic roots, rad/s, or None
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

    def divide_out_rigid_body_zeros(self, rigid: int) -> None:
        """Count and scan det Ū_all / ω^2r instead of det Ū_all.

        With r rigid-body modes det ∝ ω^2r at ω = 0: a contour that passes a
        few floors from the origin sees the phase turn 2r times faster
        than ω's own angle, and its sampling aliases (false counts of 2, 4,
        6 roots below the first elastic one). Dividing by ω^2r removes that
        known factor exactly; the roots elsewhere are unchanged. Checked
        first: the disc |ω| < floor must hold exactly 2r zeros.
        """
        if rigid and count_in_disc(self.log_det, self.floor) == 2 * rigid:
            self.log_det = deflated(self.log_det, np.zeros(rigid))
            self._divided = True

    def rigid_body_modes(self) -> int:
        """Number of zero-frequency (rigid-body) modes, as given at construction."""
        return self._rigid

    def _pencil(self, omegas, step: float = 1e-7):
        """(Ū(ω), dŪ/dω), the derivative a forward difference of ``matrix``."""
        steps = step * omegas
        stack = self.matrix(np.concatenate([omegas, omegas + steps]))
        return stack[:omegas.size], (stack[omegas.size:] - stack[:omegas.size]) / steps[:, None, None]

    def _offsets(self, omegas, full=True) -> list[np.ndarray]:
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
        A, derivative = self._pencil(omegas)
        usable = (omegas > 0) & np.isfinite(A).all(axis=(1, 2)) & np.isfinite(derivative).all(axis=(1, 2))
        rows, cols = equilibration(A[usable])
        A = rows[..., :, None] * A[usable] * cols[..., None, :]
        derivative = rows[..., :, None] * derivative[usable] * cols[..., None, :]
        try:
            pencil = _inverse_eigenvalues(np.linalg.solve(A, derivative), np.broadcast_to(full, n)[usable])
        except np.linalg.LinAlgError:
            pencil = [scipy.linalg.eigvals(a, d) for a, d in zip(A, derivative)]
        offsets, usable_offsets = [], iter(pencil)
        for ok in usable:
            mu = next(usable_offsets) if ok else np.zeros(0)
            mu = mu[np.isfinite(mu)]
            offsets.append(mu[np.argsort(np.abs(mu))])
        return offsets

    def polish(self, starts, iterations: int = 40, early: bool = False):
        """Converge on the root nearest each start, all starts at once.

        Newton for the nonlinear eigenproblem: ω ← ω − μ with μ the offset
        of smallest size. Stops at |μ| <= xtol·ω, or when the steps stop
        shrinking below UNCERTAIN·ω (the rounding floor of Ū_all); gives up
        on a start whose step twice fails to shrink above that, or is twice
        mostly imaginary and above SPLIT·ω (not near a real root).
        ``early``: also stop a round sooner where convergence to a simple root
        is quadratic (:meth:`_quadratic`), for a caller that counts all its
        roots at the end (a double root whose second offset shows only within
        1e-12 of it looks simple a round early).
        Returns a list of (root or None if it did not converge, offsets).
        """
        last_steps = self.LAST_STEPS_EARLY if early else self.LAST_STEPS
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
            for i, mu, complete in zip(active, self._offsets(omega[active], full), full):
                if mu.size == 0:
                    continue
                step = abs(mu[0])
                omega[i] -= mu[0].real
                settled = step > previous[i] / 2  # no longer shrinking: the rounding floor
                converged = (step <= self.xtol * omega[i] or (settled and step <= self.UNCERTAIN * omega[i])
                             or (early and complete and self._quadratic(step, previous[i], omega[i], mu)))
                if converged and not complete and mu.size == 1:  # its offsets are wanted too
                    previous[i] = step
                    still.append(i)
                elif converged:
                    self.last_step[omega[i]] = step / omega[i]
                    results[i] = (omega[i], mu - mu[0].real)  # offsets seen from the new ω
                else:
                    # A mostly imaginary nearest offset sees no real root at its distance:
                    # ω creeps by its real part (MLRS above 170 Hz: 40 rounds, 1e-8 each).
                    sideways = abs(mu[0].imag) > abs(mu[0].real) and step > self.SPLIT * omega[i]
                    setbacks[i] += (step >= previous[i]) + sideways
                    previous[i] = step
                    if setbacks[i] < 2:  # Newton that twice fails to shrink its step is lost
                        still.append(i)
            active = still
        return self._checked(results)

    def _checked(self, results):
        """``polish`` results less the roots accepted at the rounding floor (a last step
        above CERTIFIED_STEP) that det itself does not bear out: no sign change and no
        dip of log|det| between ω(1 ± 10·step). Where the pencil of Ū_all is not smooth,
        Newton can settle beside a root (random loops 122: 975.90 and 977.07 Hz for one
        root at 976.97, and the count bisection then gave up)."""
        doubtful = [i for i, (root, _) in enumerate(results)
                    if root is not None and self.last_step.get(root, 0.0) > CERTIFIED_STEP]
        if not doubtful:
            return results
        roots = np.array([results[i][0] for i in doubtful])
        offsets = 10 * np.array([self.last_step[root] for root in roots])
        sign, log_abs = self.log_det(np.concatenate([roots * (1 - offsets), roots, roots * (1 + offsets)]))
        sign, log_abs = np.real(sign).reshape(3, -1), log_abs.reshape(3, -1)
        borne_out = (sign[0] * sign[2] < 0) | (np.minimum(log_abs[0], log_abs[2]) > log_abs[1] + self.DIP)
        results = list(results)
        for i, ok in zip(doubtful, borne_out):
            if not ok:
                results[i] = (None, np.zeros(0))
        return results

    def _quadratic(self, step: float, previous: float, omega: float, mu: np.ndarray) -> bool:
        """Whether Newton, having just taken ``step`` after ``previous``, has converged on
        a simple root without another round.

        The step is below EARLY·ω and within 10× the square of the one before
        (quadratic convergence), and the pencil shows one near-zero offset only
        (a multiple root takes the full route). The error left is then about
        max(1e-7 (the forward difference's relative error), 10·step/ω) × step,
        under 1e-16·ω; one more round (a fifth of an MLRS solve) would only
        confirm it.
        """
        return (step <= self.EARLY * omega and step * omega <= 10 * previous ** 2
                and int(np.sum(np.abs(mu) < self.SPLIT * omega)) == 1)

    def clusters(self, starts, confirm: bool = True) -> list[list[float]]:
        """For each start, every root in the cluster around the root nearest it, ascending.

        The multiplicity of a polished root comes from :meth:`_multiplicities`
        (the offsets μ of the linearised pencil, confirmed by a root count;
        the singular values of a 60×60 Ū_all are too spread to count on);
        the other small real offsets are polished in turn and kept when they
        reach another root (farther than SPLIT: closer ones are the same,
        possibly multiple, root, and their offsets seen from it may show a
        higher multiplicity than the first arrival's did: a double root of a
        loop rigid in five directions showed its second offset only within
        1e-13 of the root). Without ``confirm`` the multiplicities are read
        from the offsets alone (see :meth:`_multiplicities`) and the member
        starts go to :attr:`deferred_members` (a simple root's pencil can show
        a spurious near offset: polishing every one cost MLRS 6 ms).
        """
        polished = self.polish(starts, early=not confirm)
        groups, members_from = [], []
        for (centre, mu), multiplicity in zip(polished, self._multiplicities(polished, confirm)):
            if centre is None:
                groups.append([])
                continue
            groups.append([centre] * multiplicity)
            real = mu[np.abs(mu.imag) <= 1e-6 * np.abs(mu)].real
            outside = np.abs(real) >= self.SPLIT * centre
            if confirm:
                near = real[outside & (np.abs(real) < self.CLUSTER_WINDOW * centre)]
                members_from += [(len(groups) - 1, centre - offset) for offset in near]
            else:  # polished only if the caller's closing count finds one missing
                near = real[outside & (np.abs(real) < self.DEFERRED_WINDOW * centre)]
                self.deferred_members += [(centre - offset, centre) for offset in near]
        if members_from:
            returned = []  # members that came back to a root of their group: more evidence
            for (g, _), result in zip(members_from, self.polish([s for _, s in members_from])):
                member = result[0]
                if member is None:
                    continue
                if all(abs(member - r) > self.SPLIT * r for r in groups[g]):
                    groups[g].append(member)
                else:
                    returned.append((g, min(groups[g], key=lambda r: abs(r - member)), result))
            for (g, root, _), multiplicity in zip(returned, self._multiplicities([r for *_, r in returned],
                                                                                confirm)):
                groups[g] += [root] * (multiplicity - groups[g].count(root))
        return [sorted(group) for group in groups]

    def _multiplicities(self, polished, confirm: bool = True) -> list[int]:
        """How many roots sit at each polished centre, given its pencil offsets mu.

        A root of multiplicity m leaves m offsets near zero, split by rounding
        to about √eps and not always real (7 arms of NAFEMS FV2: up to 6e-5).
        Where more than one offset is below SPLIT·ω, a root count over a circle
        of radius SPLIT·ω (less, if another root is nearer) decides; all those
        counts share one evaluation per refinement round. The circle holds one
        root (of some multiplicity m) at its centre and no other within twice
        its radius, so the phase turns smoothly by mπ over the half circle and
        CIRCLE_POINTS starting points (refined where log det changes fast) suffice.
        Without ``confirm`` the number of offsets below SPLIT·ω is taken as it
        is: for a caller that counts all its roots at the end anyway.
        """
        if not confirm:
            return [1 if centre is None else max(int(np.sum(np.abs(mu) < self.SPLIT * centre)), 1)
                    for centre, mu in polished]
        multiplicities = [1] * len(polished)
        asked, intervals = [], []
        for i, (centre, mu) in enumerate(polished):
            size = np.abs(mu)
            if centre is None or np.sum(size < self.SPLIT * centre) <= 1:
                continue
            farther = size[size >= self.SPLIT * centre]
            radius = min(self.SPLIT * centre, farther.min() / 2 if farther.size else np.inf)
            asked.append(i)
            intervals.append((centre - radius, centre + radius))
        counts = (count_zeros_many(self.log_det, intervals, max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS)
                  if asked else [])
        for i, count in zip(asked, counts):
            multiplicities[i] = 1 if isinstance(count, RuntimeError) else max(count, 1)
        self._counted.update((polished[i][0], multiplicities[i]) for i in asked)
        return multiplicities

    def cluster(self, omega: float) -> list[float]:
        """Every root in the cluster around the root nearest ``omega`` (see :meth:`clusters`)."""
        return self.clusters([omega])[0]

    def shrink_brackets(self, lo, hi, width: float = 1e-4) -> np.ndarray:
        """Midpoints of sign-change brackets (lo_i, hi_i) narrowed to ``width``·hi (:meth:`_narrowed`)."""
        lo, hi = self._narrowed(lo, hi, width)
        return (lo + hi) / 2

    def _narrowed(self, lo, hi, width: float, log_det=None):
        """Sign-change brackets (lo_i, hi_i) narrowed to ``width``·hi, all at once: (lo, hi).

        Each round evaluates, for every bracket (a, b) at once, the regula falsi
        point x (where the line through ±|det| at the ends crosses zero, from
        log|det| so nothing overflows), x ± 1e-4 (b − a), x ± 1e-2 (b − a) and
        NARROWING_SECTIONS − 1 equally spaced points; the bracket becomes the
        narrowest sign change among them. Near a simple root x is off by
        O((b − a)²), so a bracket shrinks up to 1e4-fold per round, and at least
        NARROWING_SECTIONS-fold anywhere. A round costs one evaluation of det
        whatever its size (MLRS: 1.1 ms, plus 0.07 ms a point): one point per
        round (Illinois regula falsi) took ten rounds where this takes three.
        ``log_det``: of another function (default: det Ū_all's).
        """
        log_det = self.log_det if log_det is None else log_det
        lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
        if lo.size == 0:
            return lo, hi
        sign, log_abs = log_det(np.r_[lo, hi])
        sign = np.real(sign)
        sign_lo, sign_hi, log_lo, log_hi = sign[:lo.size], sign[lo.size:], log_abs[:lo.size], log_abs[lo.size:]
        width = max(width, 4 * np.finfo(float).eps)
        moving = np.ones(lo.size, dtype=bool)
        sections = np.arange(1, self.NARROWING_SECTIONS) / self.NARROWING_SECTIONS
        while True:
            active = np.flatnonzero(moving & (hi - lo > width * hi))
            if active.size == 0:
                return lo, hi
            a, b = lo[active], hi[active]
            w = (b - a)[:, None]
            fraction = 1 / (1 + np.exp(np.clip(log_hi[active] - log_lo[active], -700, 700)))
            x = (a + (b - a) * fraction)[:, None]
            inside = np.sort(np.clip(np.concatenate([x + w * [-1e-2, -1e-4, 0.0, 1e-4, 1e-2],
                                                     a[:, None] + w * sections], axis=1),
                                     a[:, None] + 1e-6 * w, b[:, None] - 1e-6 * w), axis=1)
            sign_x, log_x = log_det(inside.ravel())
            points = np.concatenate([a[:, None], inside, b[:, None]], axis=1)
            signs = np.concatenate([sign_lo[active, None], np.real(sign_x).reshape(inside.shape),
                                    sign_hi[active, None]], axis=1)
            logs = np.concatenate([log_lo[active, None], log_x.reshape(inside.shape), log_hi[active, None]], axis=1)
            steps = np.where(signs[:, :-1] * signs[:, 1:] < 0, np.diff(points, axis=1), np.inf)
            k = np.argmin(steps, axis=1)
            rows = np.arange(active.size)
            lo[active], hi[active] = points[rows, k], points[rows, k + 1]
            sign_lo[active], sign_hi[active] = signs[rows, k], signs[rows, k + 1]
            log_lo[active], log_hi[active] = logs[rows, k], logs[rows, k + 1]
            moving[active] = (lo[active] != a) | (hi[active] != b)  # rounding left no point inside

    def _bracketed(self, lo, hi, log_ratio, confirm: bool = True, needed: int | None = None,
                   known=()) -> list[list[float]]:
        """The cluster of the root in each sign-change bracket (lo_i, hi_i].

        Newton starts where the straight line through |det| at the two ends
        (log_ratio = log|det(hi)| − log|det(lo)|) crosses zero; a bracket
        whose Newton lands outside it is narrowed to 1e-4 and tried again
        (a root it reached instead is kept: it is a root too). A root Newton
        still cannot reach (the orthonormalised basis can absorb a root whose
        column is all but one small component, e.g. a weak torsion mode next to
        stiff bending, so that the pencil does not show it) is taken from the
        bracket narrowed to ``xtol`` by regula falsi on det itself, as a
        simple root (a sign change: odd multiplicity; a count sees a triple one).
        With ``needed``, only the lowest ``needed`` roots (``known`` ones among them)
        matter: a bracket Newton missed above them is left out (:meth:`_needed`).
        """
        starts = lo + (hi - lo) / (1 + np.exp(np.clip(log_ratio, -700, 700)))
        groups = self.clusters(starts, confirm)
        missed = [i for i, group in enumerate(groups) if not any(lo[i] < r <= hi[i] for r in group)]
        if missed and needed is not None:
            kept = self._needed(missed, lo, hi, [r for group in groups for r in group] + list(known), needed)
            self.left_out += [(lo[i], hi[i]) for i in missed if i not in kept]
            missed = kept
        return groups + self._narrowed_groups(lo[missed], hi[missed], groups, confirm)

    def _narrowed_groups(self, lo, hi, groups, confirm: bool = True) -> list[list[float]]:
        """The clusters of the roots in sign-change brackets (lo_i, hi_i] that Newton
        missed from their first start: from the bracket narrowed to 1e-4, and, where
        that reaches no root inside either (nor did any of ``groups``), the bracket
        narrowed to xtol as a simple root (see :meth:`_bracketed`)."""
        if lo.size == 0:
            return []
        more = self.clusters(self.shrink_brackets(lo, hi), confirm)
        still = [i for i in range(lo.size) if not any(lo[i] < r <= hi[i] for group in groups + more for r in group)]
        return more + [[root] for root in self._bracket_roots(lo[still], hi[still])]

    def _needed(self, missed, lo, hi, roots, needed: int) -> list:
        """The ``missed`` brackets (indices into lo, hi) that may hold one of the lowest
        ``needed`` roots, given the ``roots`` found: those below the ``needed``-th of
        the distinct roots found, the tops of the missed brackets with no root found
        inside (each holds one of its own: a sign change), and the
        :attr:`deferred_members` that may lead to other roots (:meth:`_member_starts`:
        a close pair's other member, which no sign change shows). The members are
        likely roots, not certain ones: a bracket left out that holds one of the
        lowest ``needed`` roots is what the closing count finds missing, and its
        repairs locate it (MLRS 40 modes: five of the ten brackets Newton missed lay
        above the 40th root, 43.5 Hz, from 52.8 to 137 Hz, and narrowing them cost
        226 evaluations of det).
        Multiplicities are not relied on: they may be read from offsets alone."""
        roots = sorted(set(roots))
        empty = [i for i in missed if not any(lo[i] < r <= hi[i] for r in roots)]
        bounds = sorted(roots + [hi[i] for i in empty] + self._member_starts(roots))
        if len(bounds) < needed:
            return missed
        return [i for i in missed if lo[i] < bounds[needed - 1]]

    def _bracket_roots(self, lo, hi, log_det=None) -> list[float]:
        """One simple root in each sign-change bracket (lo_i, hi_i), the bracket narrowed
        to xtol (:meth:`_narrowed`); its width is recorded as the root's :attr:`last_step`."""
        a, b = self._narrowed(lo, hi, self.xtol, log_det)
        for root, uncertainty in zip((a + b) / 2, (b - a) / b):
            self.last_step[root] = uncertainty
        return list((a + b) / 2)

    def _roots_in(self, grid, expected: int) -> list[float]:
        """Roots inside (grid[0], grid[-1]) reached from the scan, up to ``expected`` of them.

        Polishing starts in every sign change (roots of odd multiplicity; see
        :meth:`_bracketed`), then from local minima of log|det| without a sign
        change (roots of even multiplicity, close pairs), deepest first, as
        many as the count says are still missing.
        """
        sign, log_abs = self.log_det(grid)
        found: list[float] = []
        brackets = np.flatnonzero(sign[:-1] * sign[1:] < 0)
        for members in self._bracketed(grid[brackets], grid[brackets + 1],
                                       log_abs[brackets + 1] - log_abs[brackets]):
            self._merge(found, members, grid[0], grid[-1])
        minima = _quiet_minima(sign, log_abs)
        minima = [i for i in minima[np.argsort(log_abs[minima] - np.maximum(log_abs[minima - 1],
                                                                            log_abs[minima + 1]))]
                  if not any(grid[i - 1] < r < grid[i + 1] for r in found)]
        missing = expected - len(found)
        if missing > 0 and minima:
            for members in self.clusters(grid[minima[:2 * missing]]):
                self._merge(found, members, grid[0], grid[-1])
        return sorted(found)

    def _merge(self, found: list[float], members, lo, hi) -> None:
        """Add the roots of a cluster inside (lo, hi] to ``found``, each distinct root once.

        Equal entries of ``members`` are one root's multiplicity and go in
        together; a root within SPLIT of one already found is that root (its
        multiplicity was settled by :meth:`_multiplicities`).
        """
        for value in sorted(set(m for m in members if lo < m <= hi)):
            if not any(abs(value - r) <= self.SPLIT * r for r in found):
                found += [m for m in members if m == value]

    def _split_point(self, lo, hi) -> float:
        """A point in the middle half of (lo, hi) where |det| is largest: far from any root."""
        trial = lo + (hi - lo) * np.linspace(0.3, 0.7, 9)
        return float(trial[np.argmax(self.log_det(trial)[1])])

    def _isolate(self, lo, hi, expected, found, depth=0) -> list[float]:
        """Bisect (lo, hi] on the root count until every root is found.

        found : roots already found (anywhere). Returns the roots in (lo, hi].
        Where (lo, hi] is narrower than CERTIFIED_WIDTH and float64 still finds
        fewer roots than the count (random ring 12 at 4822.65 Hz: a sign change
        that regula falsi on det could not narrow), they are all reported at its
        middle and recorded in :attr:`unseparated`. More roots found than the
        count are bisected on it too: a part it finds empty drops what was found
        there (random loops 32 at 80 modes: Newton settled at two points in an
        interval holding one root, and the search raised), and a narrow part
        with one root found takes the count's multiplicity. Raises RuntimeError
        if the count cannot be met otherwise.
        """
        inside = sorted(r for r in found if lo < r <= hi)
        narrow = hi - lo < self.CERTIFIED_WIDTH * hi
        if len(inside) == expected:
            return inside
        if len(inside) < expected and narrow:
            middle = (lo + hi) / 2  # the count encloses them: within CERTIFIED_WIDTH / 2 of it
            self.unseparated[middle] = (expected, (hi - lo) / 2)
            return [middle] * expected
        if len(inside) > expected and expected == 0:
            return []  # the count says none: what Newton settled on here is not a root
        if len(inside) > expected and narrow and len(set(inside)) == 1:
            return inside[:1] * expected  # one root, its multiplicity misread: the count's
        if depth > 60 or (len(inside) > expected and narrow):
            raise RuntimeError(f"cannot separate the {expected} roots in ({lo:.12g}, {hi:.12g}) "
                               f"rad/s in float64 (found {len(inside)}): det Ū_all is not accurate enough there, "
                               "and --digits only refines the roots float64 has found")
        found = list(found)
        if len(inside) < expected:
            (sign_lo, sign_hi), (log_lo, log_hi) = self.log_det(np.array([lo, hi]))
            if sign_lo * sign_hi < 0:  # with the bracket's own fallback where Newton cannot reach its root
                for members in self._bracketed(np.array([lo]), np.array([hi]), np.array([log_hi - log_lo])):
                    self._merge(found, members, lo, hi)
            else:
                self._merge(found, self.cluster((lo + hi) / 2), lo, hi)
            inside = sorted(r for r in found if lo < r <= hi)
            if len(inside) == expected:
                return inside
        middle = self._split_point(lo, hi)
        roots = []
        for a, b in ((lo, middle), (middle, hi)):
            roots += self._isolate(a, b, count_zeros(self.log_det, a, b), found, depth + 1)
        return sorted(roots)

    def segment(self, lo: float, hi: float, expected: int | None = None) -> list[float]:
        """Every root in (lo, hi], rad/s, ascending, repeated per multiplicity.

        The argument-principle count says how many there are; a scan with at
        least ``points_per_root`` points per counted root finds them; bisection
        on the count finds any the scan missed. A segment wider than
        SCAN_OCTAVES (the first one starts at the floor) is split by a count
        first, so an empty bottom is not scanned point by point.
        """
        if expected is None:
            expected = count_zeros(self.log_det, lo, hi)
        if expected == 0:
            return []
        if hi / lo > 2.0 ** SCAN_OCTAVES:
            middle = hi / 2.0 ** SCAN_OCTAVES
            below = count_zeros(self.log_det, lo, middle)
            return self.segment(lo, middle, below) + self.segment(middle, hi, expected - below)
        octaves = max(np.log2(hi / lo), 1.0)
        points = max(octaves * self.points_per_octave, self.points_per_root * expected)
        grid = np.geomspace(lo, hi, int(np.ceil(points)) + 1)
        return self._isolate(lo, hi, expected, self._roots_in(grid, expected))

    def _lowest(self, lo: float, hi: float, needed: int | None) -> list[float]:
        """The roots in (lo, hi], or only enough of the lowest to give ``needed``.

        A segment holding far more roots than needed is halved (geometrically)
        and its upper half searched only if the lower one falls short.
        """
        expected = count_zeros(self.log_det, lo, hi)
        if needed is not None and expected > 2 * needed + 4 and hi > lo * (1 + 1e-3):
            middle = float(np.sqrt(lo * hi))
            lower = self._lowest(lo, middle, needed)
            return lower if len(lower) >= needed else lower + self._lowest(middle, hi, needed - len(lower))
        return self.segment(lo, hi, expected)

    def find_near(self, guesses, count: int) -> list[float]:
        """The lowest ``count`` roots, warm-started from ``guesses`` (rad/s).

        Guesses (e.g. the roots of a neighbouring scene of the same model) are
        taken as predictions (:func:`~linmstmm.predicted.predicted_roots`: the
        secant on det, one certifying count); where that cannot certify them,
        they are polished on the pencil and one count over (floor, just above
        the count-th root) must confirm that none was missed. Otherwise the
        full search runs.
        """
        guesses = np.sort(np.asarray(guesses, dtype=float))
        found = predicted_roots(self, guesses, count) if guesses.size >= count else None
        if found is not None:
            return self._separated_above_floor(found)[:count]
        found = self._confirmed(self._polished(guesses, []), count)
        return found if found is not None else self._search(count, None)

    def _polished(self, starts, found: list[float], confirm: bool = True) -> list[float]:
        """``found`` with the roots (and their clusters) Newton reaches from ``starts``."""
        return self._with_groups(found, self.clusters(starts, confirm))

    def _with_groups(self, found: list[float], groups) -> list[float]:
        """``found`` (left as it is) with each group's roots merged in (:meth:`_merge`), ascending."""
        found = list(found)
        for members in groups:
            self._merge(found, members, self.floor, np.inf)
        return sorted(found)

    def _confirmed(self, found: list[float], count: int | None, omega_max: float | None = None,
                   cap: float = np.inf):
        """The lowest ``count`` of ``found`` (or all up to omega_max) if one count from
        the floor says there are no others below them; None otherwise.
        ``cap``: the count stops there at the latest (rad/s; above the count-th root).
        Multiplicities above one inside the count are counted over circles first
        (:meth:`_settled`)."""
        found = self._settled(found, count, omega_max, cap)
        upper = self._count_top(found, count, omega_max)
        if upper is None or (count is not None and len(found) >= count and found[count - 1] >= cap):
            return None
        upper = min(upper, cap)
        below = [r for r in found if r < upper]
        return below[:count] if self.confirm_no_other_zeros(found, upper) else None

    def _settled(self, found: list[float], count: int | None, omega_max: float | None,
                 cap: float = np.inf) -> list[float]:
        """``found`` with every multiplicity above one below the closing count's top (and
        ``cap``) counted over a circle (:meth:`_recounted`), again while that moves the
        top up. The closing count sees zeros less the roots divided out: a simple root
        read as double from a spurious near-zero pencil offset would cancel a missing
        root (a random tree at 40 modes read one as fivefold, with four missing, and
        passed; MLRS above 400 Hz read 53 of 78 roots as double)."""
        while True:
            found = self._as_counted(found)
            top = min(self._count_top(found, count, omega_max) or np.inf, cap)
            doubtful = sorted({r for r in found if r < top and r not in self._counted and found.count(r) > 1})
            if not doubtful:
                return found
            found = self._recounted(found, doubtful)

    def _count_top(self, found: list[float], count: int | None, omega_max: float | None):
        """Top of the closing count: midway between the count-th root and the next one
        found (1 % above it if none), or omega_max, whichever is lower; omega_max with
        fewer than ``count`` found, None without it."""
        if count is None or len(found) < count:
            return omega_max
        top = found[count - 1]
        above = [r for r in found if r > top * (1 + self.SAME_ROOT)]
        by_count = (top + above[0]) / 2 if above else top * 1.01
        return by_count if omega_max is None else min(by_count, omega_max)

    def _recovered(self, found: list[float], upper: float, count: int | None = None):
        """(``found`` with the roots below ``upper`` that the closing count says are
        missing, the cap for the closing count that follows (rad/s)).

        They are located by geometric bisection from :attr:`root_free_below` up,
        down to eighths of an octave, on counts of det with the ``found`` roots
        divided out (:func:`~linmstmm.counting.deflated`; all intervals of one
        level in one batched count). With ``count``, an
        interval with at least ``count`` roots (found or missing) below it is
        not split further: its roots are above the count-th, and the closing
        count is capped at its lower end. The intervals that
        hold some are scanned densely, and det on that scan with the found roots
        divided out has sign changes and quiet minima of the missing roots alone,
        again with each pass's roots divided out (:meth:`_rescanned`: of a close pair
        missing in one scan step, one shows only once the other is found; random
        floating_loops 3 at 80 modes fell back to the segment search, 1.4 s more).
        ``found`` as it was if a count cannot be made.
        """
        reduced = deflated(self.log_det, [r for r in found if r < upper])
        try:
            missing = count_zeros(reduced, self.floor, upper, max_points=DEFLATED_MAX_POINTS)
        except RuntimeError:
            return found, upper
        floor = min(self.root_free_below, upper)  # the bisection starts above what a count found empty
        pending, leaves, cap = [(floor, upper, missing)] if missing else [], [], upper
        while pending:
            kept, level_cap = self._below_count(leaves + pending, found, count, upper)
            cap = min(cap, level_cap)
            leaves, pending = [part for part in leaves if part in kept], [part for part in pending if part in kept]
            leaves += [part for part in pending if part[1] / part[0] <= 2 ** 0.125]
            wide = [part for part in pending if part[1] / part[0] > 2 ** 0.125]
            middles = [np.sqrt(lo * hi) for lo, hi, _ in wide]
            lower = (count_zeros_many(reduced, [(lo, mid) for (lo, _, _), mid in zip(wide, middles)],
                                      max_points=DEFLATED_MAX_POINTS) if wide else [])
            if any(isinstance(c, RuntimeError) for c in lower):
                return found, upper
            pending = [part for (lo, hi, k), mid, c in zip(wide, middles, lower)
                       for part in ((lo, mid, c), (mid, hi, k - c)) if part[2] > 0]
        if not leaves:
            return found, cap
        grid = np.concatenate([np.geomspace(lo, hi, 16 * k + 17) for lo, hi, k in leaves])
        return self._rescanned(found, [(grid, *self.log_det(grid))], upper), cap

    @staticmethod
    def _below_count(parts, found: list[float], count: int | None, upper: float):
        """(the (lo, hi, missing) ``parts`` that may hold one of the lowest ``count``
        roots, the lower end of the first that cannot, else ``upper``): a part
        with ``count`` roots below it, found or missing, cannot."""
        kept, missing_below = [], 0
        for lo, hi, missing in sorted(parts):
            if count is not None and sum(r < lo for r in found) + missing_below >= count:
                return kept, lo
            kept.append((lo, hi, missing))
            missing_below += missing
        return kept, upper

    def confirm_no_other_zeros(self, known: list[float], upper: float) -> bool:
        """True if (floor, upper) holds no zeros of det Ū_all but ``known``.

        The count runs on det with the known roots divided out (:func:`~linmstmm.counting.deflated`),
        so its phase turns only for zeros not in ``known`` (or by −π for a
        ``known`` one that is not a zero) and DEFLATED_POINTS starting points
        suffice where counting them all took four times as many. Known
        roots above ``upper`` are divided out too: outside the contour they
        change nothing, and the next root just above ``upper`` no longer turns
        the phase fast near the contour's end (MLRS 20 modes: three refinement
        rounds fewer). False also where it cannot count: the segment search then
        decides (and says so if it cannot either).
        """
        return self.other_zeros(known, None, upper) == 0

    def other_zeros(self, known: list[float], lo: float | None, hi: float) -> int | None:
        """Zeros of det Ū_all in (lo, hi) less those in ``known`` (negative where a known
        one is not a zero); lo None: the floor. None where the count cannot be made."""
        try:
            return count_zeros(deflated(self.log_det, known), self.floor if lo is None else lo, hi,
                               max_points=DEFLATED_MAX_POINTS, initial_points=DEFLATED_POINTS)
        except RuntimeError:
            return None

    def _scan_ahead(self, count: int | None, omega_max: float | None):
        """Guess, polish, confirm: the fast path of :meth:`find`, or None.

        A coarse scan (``points_per_octave`` above FINE_SCAN_RATIO × scale, an eighth
        of it below) goes up in chunks (to FIRST_CHUNK_RATIO × scale, then up to ×4 each, less where
        the candidates so far extrapolate to ``count`` sooner: :meth:`_next_top`;
        see :meth:`_scanned`)
        until it has seen ``count`` candidates (sign changes, and minima of
        log|det| without one), reached ``omega_max``, or scanned a chunk
        without a new candidate; all are polished at once (more chunks if their
        multiplicities leave fewer than ``count`` roots) and one count from
        the floor must agree. Multiplicities are
        read from the pencil offsets; those above one are counted over a circle
        first (a spurious one would cancel a missing root in that count), and a
        simple one misread changes the total, which that count sees. If the count
        finds more, the repairs of :meth:`_closed` follow (the deferred cluster
        members, the stored scan with the found roots divided out, deflated
        counts, recounted multiplicities), each
        followed by the closing count again. Far fewer
        evaluations than the segment search when it works; when it does not
        (a root between two candidates, a chain of clusters), :meth:`find`
        falls back.
        """
        found: list[float] = []
        self.deferred_members, self.left_out, self.root_free_below = [], [], self.floor
        brackets, minima = [], []  # (lo, hi, log|det(hi)| − log|det(lo)|) and grid points
        lo, hi = self.floor, FIRST_CHUNK_RATIO * self.scale
        scans = [(np.zeros(0),) * 3]  # every chunk's (grid, sign, log|det|), kept for _rescanned
        while True:
            if omega_max is not None:
                hi = min(hi, omega_max)
            grid, sign, log_abs = scan = self._scanned(lo, hi, scans[-1])
            scans.append(scan)
            change = np.flatnonzero(sign[:-1] * sign[1:] < 0)
            change = change[grid[change + 1] > lo]  # (the lower chunk's own were taken there)
            waiting = len(brackets) + len(minima)
            brackets += zip(grid[change], grid[change + 1], log_abs[change + 1] - log_abs[change])
            minima += list(grid[_quiet_minima(sign, log_abs)])
            # A chunk with few new candidates (a quarter of those seen, or none) after some:
            # polish those; their multiplicities (a chain's triple roots are one sign change
            # each) and the close pairs their pencils point at (no sign change where both
            # share a scan step) may make up the count, where scanning on for more would
            # polish roots far above it (MLRS 40 modes: up to 240 Hz for a 43.5 Hz count).
            new = len(brackets) + len(minima) - waiting
            stalled = count is not None and waiting > 0 and new <= (len(found) + waiting) / 4
            if (omega_max is not None and hi >= omega_max or stalled
                    or count is not None and len(found) + len(brackets) + len(minima) >= count):
                if count is not None:  # only the lowest candidates matter
                    keep = sorted([(b[0], b) for b in brackets] + [(m, None) for m in minima])[:count - len(found)]
                    brackets = [b for _, b in keep if b is not None]
                    minima = [m for m, b in keep if b is None]
                found = self._polished(minima, found, confirm=False)
                if brackets:
                    found = self._with_groups(found, self._bracketed(*map(np.array, zip(*brackets)), confirm=False,
                                                                     needed=count, known=found))
                brackets, minima = [], []
                if count is not None and found and len(found) < count:  # pairs hidden in one scan step?
                    found = self._with_members(found, found[-1])
                if count is not None and len(found) < count and self.left_out:  # each holds a root
                    found = self._with_left_out(found, count - len(found))
                if omega_max is not None and hi >= omega_max or count is not None and len(found) >= count:
                    return self._closed(found, count, omega_max, scans)
            # fewer roots than count? (sign changes only: a shallow quiet minimum far
            # below the first root is no evidence that the roots have run out)
            seen = found + [b[0] for b in brackets]
            if omega_max is None and (hi >= self.ceiling or (seen and hi > 1e3 * max(seen))):
                return None
            lo, hi = hi, self._next_top(hi, sorted(seen + minima), count)

    def _closed(self, found: list[float], count: int | None, omega_max: float | None, scans):
        """``found`` as the closing count confirms it (:meth:`_confirmed`), after the
        repairs it takes, each followed by that count again; None if none is enough.

        Every closing count first has the multiplicities above one inside it
        counted over circles (:meth:`_settled`). The repairs:

        1. The deferred cluster members polished (:meth:`_with_members`: a close
           pair's other member, which the pencil at the found one points at).
        2. The roots the scan's own values show once ``found`` is divided out
           (:meth:`_rescanned`; no new scan): two roots in one grid step, one of
           them found.
        3. The roots still missing, located by deflated counts (:meth:`_recovered`),
           below the count's top or, with fewer than ``count`` found, below the
           highest root found.
        4. Every multiplicity recounted: one read as simple may be double. Last,
           as the rarest and dearest: a circle's count per root (MLRS 50 modes:
           850 contour points, 1 s, where the recovery alone was enough).

        All look only below the closing count's top (the scan may have gone far
        past the count-th root: a 40-mode beam's recount of all it saw cost 1000
        contour points).
        """
        def top(roots):
            return self._count_top(roots, count, omega_max) or np.inf

        found = self._settled(found, count, omega_max)
        confirmed = self._confirmed(found, count, omega_max)
        for repair in (lambda roots: self._with_members(roots, top(roots)),
                       lambda roots: self._rescanned(roots, scans, top(roots))):
            if confirmed is not None:
                break
            repaired = repair(found)
            if repaired != found:
                found = repaired
                confirmed = self._confirmed(found, count, omega_max)
        upper = None
        if confirmed is None and found:  # with fewer than count found (misread multiplicities
            # recounted), the missing may still be below the highest: look there
            upper = self._count_top(found, count, omega_max) or found[-1] * (1 + self.CLUSTER_WINDOW)
        if upper is not None:
            found, cap = self._recovered(found, upper, count)
            confirmed = self._confirmed(found, count, omega_max, cap)
            if confirmed is None:
                recounted = self._recounted(found, [r for r in sorted(set(found)) if r < min(top(found), cap)])
                confirmed = None if recounted == found else self._confirmed(recounted, count, omega_max, cap)
        return confirmed

    def _with_members(self, found: list[float], upper: float) -> list[float]:
        """``found`` with the roots Newton reaches from the :attr:`deferred_members` below
        ``upper``, which leave the list: not those within SPLIT of a root found (Newton
        would return to it) or of a lower start (the same root)."""
        starts = self._member_starts(found, upper)
        self.deferred_members = [member for member in self.deferred_members if member[0] >= upper]
        return self._polished(starts, found, confirm=False) if starts else found

    def _with_left_out(self, found: list[float], missing: int) -> list[float]:
        """``found`` with the roots of the lowest ``missing`` :attr:`left_out` brackets,
        which leave the list: where the found roots and the members fell short of the
        count that left them out, each is a root the count may need (left for the scan
        to go on, random ring 3 at 80 modes was scanned up to 1e9 rad/s, its new
        brackets left out each time). The others stay out: the roots missing may be
        lower (pairs hidden in a scan step), for the closing count to find."""
        self.left_out.sort()
        lo, hi = map(np.array, zip(*self.left_out[:missing]))
        self.left_out = self.left_out[missing:]
        return self._with_groups(found, self._narrowed_groups(lo, hi, [found], confirm=False))

    def _member_starts(self, found: list[float], upper: float = np.inf) -> list[float]:
        """The :attr:`deferred_members` below ``upper`` that may lead to a root not in
        ``found``: not those within SPLIT of a root found (Newton would return to it)
        or of a lower start (the same root), ascending."""
        starts: list[float] = []
        for start, origin in sorted(self.deferred_members):
            near = self.MEMBER_OVERLAP * abs(start - origin)
            if start < upper and all(abs(start - r) > max(self.SPLIT * r, near * (r != origin))
                                     for r in found + starts[-1:]):
                starts.append(start)
        return starts

    def _rescanned(self, found: list[float], scans, upper: float = np.inf) -> list[float]:
        """``found`` with the roots below ``upper`` that the fast scan's values (``scans``:
        (grid, sign, log|det|) per chunk) show once ``found`` is divided out (:func:`divided_out`).

        Two roots in one grid step give det no sign change there, nor does a
        root hidden beside a found one; the deflated det changes sign at the
        missing one. Only values already computed are looked at; the
        candidates are then handled as in :meth:`_recovered`. A root found so
        can hide the next one in the same step: up to RESCANS passes, while
        each finds more.
        """
        grid, sign, log_abs = (np.concatenate(parts) for parts in zip(*scans))
        grid, first = np.unique(grid, return_index=True)
        first = first[:np.searchsorted(grid, upper) + 1]  # the step across upper too
        grid, sign, log_abs = grid[:first.size], sign[first], log_abs[first]
        for _ in range(self.RESCANS if grid.size >= 3 else 0):
            more = self._deflated_candidates(found, [grid], *divided_out(grid, sign, log_abs, found),
                                             deflated(self.log_det, found))
            if more == found:
                break
            found = more
        return found

    def _deflated_candidates(self, found: list[float], grids, sign, log_abs, reduced) -> list[float]:
        """``found`` with the roots in the sign changes and quiet minima of a deflated scan:
        ``grids`` (ascending arrays) with the (phase, log|·|) of ``reduced`` (deflated
        det) at their points, concatenated. A sign change is narrowed to xtol by
        regula falsi on ``reduced`` (a missing root may share a grid step with a
        found one, where Newton would return to that); a minimum is polished."""
        brackets, minima = [], []
        for grid, piece_sign, piece_log in zip(grids, *(np.split(v, np.cumsum([g.size for g in grids])[:-1])
                                                         for v in (np.real(sign), log_abs))):
            change = np.flatnonzero(piece_sign[:-1] * piece_sign[1:] < 0)
            brackets += zip(grid[change], grid[change + 1])
            minima += list(grid[_quiet_minima(piece_sign, piece_log)])
        found = self._polished(minima, found, confirm=False)
        if not brackets:
            return found
        return self._with_groups(found, [[root] for root in self._bracket_roots(*map(np.array, zip(*brackets)),
                                                                                  log_det=reduced)])

    def _recounted(self, found: list[float], roots) -> list[float]:
        """``found`` with the multiplicity of each of ``roots`` (distinct, in ``found``)
        counted over a small circle (all circles in one count; see :meth:`_multiplicities`)
        instead of read from its pencil offsets, which can show spurious near-zero ones
        or (a Newton stopped early) miss a double root's second one. Where a circle
        cannot be counted the root is taken as simple: an unconfirmed multiplicity could
        hide a missing root from the closing count, a missing one cannot."""
        self._counted.update((r, count or 1) for r, count in zip(roots, self.multiplicities(roots, sorted(set(found)))))
        return self._as_counted(found)

    def _as_counted(self, found: list[float]) -> list[float]:
        """``found`` with each root repeated as often as a circle count gave it (:attr:`_counted`),
        the others as often as they are."""
        return sorted(r for r in set(found) for _ in range(self._counted.get(r, found.count(r))))

    def _circle_radius(self, root: float, others) -> float:
        """Radius (rad/s) of the circle that counts the multiplicity of ``root``: SPLIT·ω,
        less where a root of ``others`` is nearer (half the distance)."""
        return min([self.SPLIT * root] + [abs(root - other) / 2 for other in others if other != root])

    def multiplicities(self, roots, others=()) -> list:
        """How many roots sit at each of ``roots`` (rad/s, roots found), counted over a
        circle of radius SPLIT·ω, less where a root of ``others`` is nearer (all
        circles in one count; see :meth:`_multiplicities`); None where the count
        cannot be made."""
        if not len(roots):
            return []
        radii = [self._circle_radius(r, others) for r in roots]
        counts = count_zeros_many(self.log_det, [(r - radius, r + radius) for r, radius in zip(roots, radii)],
                                  max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS)
        return [None if isinstance(c, RuntimeError) else max(c, 1) for c in counts]

    def unseparated_among(self, roots) -> dict:
        """The :attr:`unseparated` entries of ``roots`` (rad/s), ascending."""
        return {r: self.unseparated[r] for r in sorted(set(roots)) if r in self.unseparated}

    def multiplicity(self, root: float, others=()) -> int | None:
        """How many roots sit at ``root``: the circle count already made for it while
        finding the roots, else one made now (:meth:`multiplicities`)."""
        return self._counted.get(root) or self.multiplicities([root], others)[0]

    def _scanned(self, lo: float, hi: float, below) -> tuple:
        """(grid, sign, log|det|) of the fast scan over [lo, hi], led by the last two
        points of ``below`` (the chunk under it, same form): a sign change or a
        quiet minimum at the edge between two chunks is seen (a double root of a
        round tube 1 % below a chunk's top was missed), and lo is not evaluated
        twice. The first chunk, 13 octaves from the floor that hold no root in
        most models, is left out if a cheap count finds none there (and
        :attr:`root_free_below` says so)."""
        tail = tuple(part[-2:] for part in below)
        if lo == self.floor and self._holds_no_roots(lo, hi):
            self.root_free_below = hi
            return tail
        grid = self._quick_grid(lo, hi)
        grid = grid[1:] if tail[0].size and grid[0] == tail[0][-1] else grid
        sign, log_abs = self.log_det(grid)
        return np.r_[tail[0], grid], np.r_[tail[1], sign], np.r_[tail[2], log_abs]

    def _holds_no_roots(self, lo: float, hi: float) -> bool:
        """True if a count over (lo, hi) from DEFLATED_POINTS starting points finds
        no root (False also when it cannot count)."""
        try:
            return count_zeros(self.log_det, lo, hi, initial_points=DEFLATED_POINTS) == 0
        except RuntimeError:
            return False

    def _quick_grid(self, lo: float, hi: float) -> np.ndarray:
        """The fast path's scan of [lo, hi]: points_per_octave above FINE_SCAN_RATIO × scale,
        an eighth below."""
        def geometric(a, b, per_octave):
            return np.geomspace(a, b, 1 + int(np.ceil(per_octave * np.log2(b / a)))) if b > a else np.zeros(0)
        fine = FINE_SCAN_RATIO * self.scale
        return np.unique(np.r_[geometric(lo, min(hi, fine), self.points_per_octave / 8),
                               geometric(max(lo, fine), hi, self.points_per_octave)])

    def find(self, count: int | None, omega_max: float | None) -> list[float]:
        """Elastic roots (rad/s) ascending, each repeated per multiplicity.

        The lowest ``count``, or all up to ``omega_max``, with none missed:
        from the predictor's frequencies when one count confirms them
        (:func:`~linmstmm.predicted.predicted_roots`, with ``count``), else the
        fast path (:meth:`_scan_ahead`) when one count confirms it, else the
        segment search (:meth:`_search`).
        """
        if count is not None and self.predictor is not None:
            predictions = self.predictor(count + PREDICTION_MARGIN + count // 10)
            found = predicted_roots(self, predictions, count) if self._usable(predictions) else None
            if found is not None:  # certified up to above the count-th: complete below omega_max too
                found = self._separated_above_floor(found)
                return [w for w in found[:count] if omega_max is None or w <= omega_max]
        found = self._scan_ahead(count, omega_max) if count is not None or omega_max is not None else None
        if found is None:
            found = self._search(count, omega_max)
        found = self._separated_above_floor(found)
        return found[:count] if count is not None else found

    def _separated_above_floor(self, found: list[float]) -> list[float]:
        """``found`` (rad/s) with each multiple root that is a cluster split into its roots
        (:meth:`_separated`), then checked for roots below the floor (:meth:`_check_floor`)."""
        found = self._separated(found)
        self._check_floor(found)
        return found

    def _usable(self, predictions: np.ndarray) -> bool:
        """False where the lowest prediction (rad/s) is below FLOOR_MARGIN floors: the
        coarse model's eigenvalues there are rounding of its stiffest ones (a strip with
        bending stiffnesses 1e10 apart predicted 0 Hz), and the scan from the floor
        decides instead (:meth:`_check_floor` says so if a root lies below it)."""
        return not (predictions.size and predictions[0] < FLOOR_MARGIN * self.floor)

    def _check_floor(self, found: list[float]) -> None:
        """Raise RuntimeError if det has zeros below the floor besides the rigid-body
        modes' (every count starts there, so such roots would be missing from the
        list without a word: a cantilever with Iy = 1e-20 m⁴ has its first four
        between 1.5e-6 and 7e-5 Hz). Checked with one count in that disc, only where
        the lowest root found is within FLOOR_CHECK times the floor."""
        if not found or found[0] > FLOOR_CHECK * self.floor:
            return
        expected = 0 if self._divided else 2 * self._rigid
        try:
            below = count_in_disc(self.log_det, self.floor)
        except RuntimeError:
            below = None
        if below != expected:
            raise RuntimeError(f"det Ū_all has zeros below {self.floor:.3g} rad/s "
                               f"({self.floor / (2 * np.pi):.3g} Hz) besides the rigid-body modes', which "
                               "the root search cannot certify: use `linmstmm fe` for this model")

    def _separated(self, roots: list[float]) -> list[float]:
        """``roots`` with each multiple one that is a cluster of distinct roots split into them.

        Roots closer than SPLIT are counted as one multiple root (a circle of that
        radius holds them all). Each multiple root is counted again over a circle
        100 times smaller (all in one count): a multiple root keeps its count, a
        cluster does not, and its members are then isolated by bisection on the
        count within the first circle (:meth:`_isolate`). A random loop's double
        root and the simple one 1.9e-5 above it had come back as one triple root.
        Where float64 cannot separate them they stay together, and
        :attr:`unseparated` says so (root -> (multiplicity, radius, rad/s)):
        ``natural_frequencies`` then separates them in mpmath
        (:func:`~linmstmm.precision.separated_cluster`), or names them in its note.
        """
        distinct = sorted(set(roots))
        # (a list cut at a count may hold one copy of a root counted as multiple)
        multiple = [r for r in distinct if max(roots.count(r), self._counted.get(r, 1)) > 1]
        if not multiple:
            return roots
        radii = [self._circle_radius(r, distinct) for r in multiple]
        tight = count_zeros_many(self.log_det, [(r - radius / 100, r + radius / 100)
                                                for r, radius in zip(multiple, radii)],
                                 max_points=CIRCLE_MAX_POINTS, initial_points=CIRCLE_POINTS)
        separated = list(roots)
        for r, radius, count in zip(multiple, radii, tight):
            m = self._counted.get(r, roots.count(r))  # (``roots`` may end inside a multiple root)
            if count == m or (r == distinct[-1] and count > roots.count(r)):
                continue
            try:
                members = self._isolate(r - radius, r + radius, m, [r])
            except RuntimeError:
                self.unseparated[r] = (m, radius)
                continue
            separated = [x for x in separated if x != r] + members[:roots.count(r)]
        return sorted(separated)

    @staticmethod
    def _next_top(lo: float, roots: list[float], count: int | None) -> float:
        """Top of the next segment: four times ``lo``, or less if the roots found so
        far say ``count`` is reached sooner (a beam's ω_n grows like n², a
        chain's like n: the n² guess overshoots, which costs less than a miss)."""
        if count is None or len(roots) < 2:
            return 4 * lo
        guess = roots[-1] * ((count + 2) / len(roots)) ** 2
        return min(4 * lo, max(1.25 * lo, guess))

    def _search(self, count: int | None, omega_max: float | None) -> list[float]:
        """Elastic roots (rad/s) ascending, each repeated per multiplicity.

        The lowest ``count``, or all up to ``omega_max``, with none missed:
        each scanned segment is checked against the root count. Scans
        upwards from the floor, the first segment up to FIRST_SEGMENT_RATIO ×
        scale. Fewer than ``count`` come back if there are no more below the
        ceiling.
        """
        roots: list[float] = []
        start = FIRST_SEGMENT_RATIO * self.scale
        lo, hi = self.floor, min(start, omega_max) if omega_max else start
        while True:
            try:
                roots += self._lowest(lo, hi, None if count is None else count - len(roots))
            except RuntimeError as error:
                if not roots or lo < 100 * roots[-1]:
                    raise
                # Far above the last root of a discrete model, Ū_all is dominated by
                # inertia (ω² m / k beyond 1e15): stop there and say so.
                self.note = (f"the search stopped at {lo:.4g} rad/s, {lo / roots[-1]:.2g} times the highest, "
                             f"where inertia swamps det Ū_all ({error})")
                break
            done_by_count = count is not None and len(roots) >= count
            done_by_range = omega_max is not None and hi >= omega_max
            if done_by_count or done_by_range or hi >= self.ceiling:
                break
            lo, hi = hi, self._next_top(hi, roots, count)
            if omega_max is not None:
                hi = min(hi, omega_max)
        return roots[:count] if count is not None else roots


def _inverse_eigenvalues(stack, full, iterations: int = 6) -> list[np.ndarray]:
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


def _quiet_minima(sign, log_abs) -> np.ndarray:
    """Indices of a scan's interior local minima of log|det| with no sign change on
    either side: where a root of even multiplicity or a close pair may hide."""
    inner = np.arange(1, len(sign) - 1)
    return inner[(log_abs[inner] < log_abs[inner - 1]) & (log_abs[inner] < log_abs[inner + 1])
                 & (sign[inner - 1] == sign[inner]) & (sign[inner] == sign[inner + 1])]
