"""Speed of the transfer-matrix solve against the FE route on the same files, measured in one run.

    python benchmarks/bench_speed.py [--quick] [--out reports]

Writes ``OUT/speed.md`` and ``OUT/figures/speed_vs_fe.png`` (``--quick``: fewer
counts and rounds, into a temporary folder unless ``--out`` is given). Every
figure is a ratio or a time from this one run; nothing is a unit test.

Measured per model (the launcher-size files in models/):

* one evaluation of det Ū_all, warm: the compiled kernels at a single ω and
  per ω in a batch of 512, on one thread and shared among the cores
  (:mod:`linmstmm.spread`), and the numpy carry likewise; one Wittrick–Williams
  count J(ω), which makes the closing counts;
* the first N natural frequencies (N = 10, 20, 60, 100) by
  ``natural_frequencies(engine="compiled")``, warm kernels: wall time of the
  first solve of a model object (its compilation included:
  :mod:`linmstmm.compiled_model`) and of a solve of a model already compiled
  (the counterpart of the FE eigensolvers' times, which exclude assembly),
  evaluations of det Ū_all per root, and the largest relative difference from
  the FE route's automatic refinement at rtol 1e-10 (an independent check);
  the same with ``rtol=1e-9`` asked for (certified to 1e-9, lone roots listed
  unpolished where the counts certify them), beside the default (polished to rounding);
* the FE route on the coarsest mesh (elements per beam doubled from 1, at most
  128) whose first N frequencies are within 1e-9 of the transfer-matrix ones
  (1e-6 for N >= 60), or the closest where none is: dense LAPACK
  ``eigh(K, M, subset_by_index=…)`` (up to DENSE_LIMIT unknowns) and sparse
  shift-invert ``eigsh``, assembly excluded, the faster of the two taken as
  the FE baseline; and the ``fe`` command's own automatic refinement
  (``fe_frequencies``);
* the first 10 and 20 mode shapes by both engines beside FE ``eigsh`` returning its
  eigenvectors on the same mesh;
* the start-up of a new process running the README's main command, and new processes
  of the ``response`` command on the bundled load cases.
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import scipy.linalg as la
import scipy.sparse.linalg as sla

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

from common import beam_chain_file, cantilever_reference  # noqa: E402
from time_budget import time_budget  # noqa: E402

from linmstmm import spread  # noqa: E402
from linmstmm.coarse_prediction import predict_frequencies  # noqa: E402
from linmstmm.compiled_model import forget_compiled_models  # noqa: E402
from linmstmm.deduction import Deduction  # noqa: E402
from linmstmm.determinant import CompiledDeterminant, NumpyDeterminant, load_kernels  # noqa: E402
from linmstmm.fe import assemble, fe_frequencies  # noqa: E402
from linmstmm.model import Beam, Model, load_model  # noqa: E402
from linmstmm.modes import mode_shapes  # noqa: E402
from linmstmm.nullspace import release_indeterminate  # noqa: E402
from linmstmm.solve import natural_frequencies  # noqa: E402
from linmstmm.threads import one_blas_thread  # noqa: E402
from linmstmm.topology import build_topology  # noqa: E402
from linmstmm.wittrick_williams import ModeCounter  # noqa: E402

#: Degrees of freedom above which the dense eigensolver is not timed (sparse eigsh wins there).
DENSE_LIMIT = 2000
MODELS = {"launcher (models/mlrs/mlrs.toml)": REPO / "models" / "mlrs" / "mlrs.toml",
          "launcher 2 (models/launcher2/launcher2.toml)": REPO / "models" / "launcher2" / "launcher2.toml"}

#: The bundled load cases and their models, timed as new processes of the ``response`` command.
RESPONSE_CASES = (("models/mlrs/mlrs.toml", "models/loads/mlrs_firing.toml"),
                  ("models/cantilever_tip_mass.toml", "models/loads/cantilever_step.toml"))


def best_time(function, rounds: int) -> tuple[float, object]:
    """(best wall time s, last result) over ``rounds`` calls after one warm-up."""
    result = function()
    best = np.inf
    for _ in range(rounds):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def evaluation_costs(model, rounds: int) -> dict:
    """Seconds per evaluation of det Ū_all: compiled and numpy, single ω and batched."""
    deduction = Deduction(build_topology(model))
    release_indeterminate(deduction)
    compiled, reference = CompiledDeterminant(deduction), NumpyDeterminant(deduction)
    omegas = np.geomspace(1.0, 2e4, 512)
    singles = omegas[::8]
    costs = {}
    for name, engine in (("compiled", compiled), ("numpy", reference)):
        single = best_time(lambda: [engine.log_det(w) for w in singles], rounds)[0] / singles.size
        with one_core():
            batch = best_time(lambda: engine.log_det(omegas), rounds)[0] / omegas.size
        shared = best_time(lambda: engine.log_det(omegas), rounds)[0] / omegas.size
        costs[name] = (single, batch, shared if name == "compiled" else np.nan)
    return costs


@contextmanager
def one_core():
    """Inside, the compiled kernels' batches stay on the calling thread (:mod:`linmstmm.spread`)."""
    original = spread.cores
    spread.cores = lambda: 1
    try:
        yield
    finally:
        spread.cores = original


def first_solve(model, count: int, rounds: int, engine: str = "compiled", **options) -> tuple[float, object]:
    """(best wall time s, result) of ``natural_frequencies`` solving ``model`` for the first
    time: the compiled models are forgotten before each round (untimed), so each
    round compiles it again (:mod:`linmstmm.compiled_model`), as a new process does.
    options: more arguments of ``natural_frequencies`` (``rtol``)."""
    best, result = np.inf, None
    for _ in range(rounds):
        forget_compiled_models()
        start = time.perf_counter()
        result = natural_frequencies(model, count, engine=engine, **options)
        best = min(best, time.perf_counter() - start)
    return best, result


def first_solves_beside_fe(model, count: int, rounds: int) -> tuple[float, float, float, object]:
    """(best first solve s at the default, best first solve s at ``rtol=ASKED_RTOL``, best
    ``fe`` command s, the latter's MSTMM result): in every round one of each in turn
    (:func:`first_solve`'s way; ``fe_frequencies`` at its defaults, rtol 1e-9, as the
    ``fe`` command runs), so that a busy spell of the machine falls on all three alike."""
    default = asked = fe = np.inf
    result = None
    for _ in range(rounds):
        default = min(default, first_solve(model, count, 1)[0])
        seconds, result = first_solve(model, count, 1, rtol=ASKED_RTOL)
        asked = min(asked, seconds)
        start = time.perf_counter()
        fe_frequencies(model, count)
        fe = min(fe, time.perf_counter() - start)
    return default, asked, fe, result


def solve_again(model, count: int, engine: str = "compiled", **options):
    """``natural_frequencies`` of a model compiled already (its program, counter and coarse
    pencil kept), its coarse predictions solved afresh as the FE eigensolver's are timed:
    the same request made twice in a row would take the kept ones
    (:func:`linmstmm.coarse_prediction.predict_frequencies`)."""
    predict_frequencies.cache_clear()
    return natural_frequencies(model, count, engine=engine, **options)


#: The accuracies of the speed–accuracy table (None: the default, certified to 1e-9 and
#: polished to rounding).
RTOLS = (None, 1e-9, 1e-6, 1e-4)
#: The rtol of the second table of each model: the default's certified accuracy, asked for.
ASKED_RTOL = 1e-9


def rtol_table(model, counts, rounds: int) -> list[str]:
    """Markdown table: the first N at each of RTOLS, by both engines, first solve and
    compiled model (:func:`interleaved_rtols`), with the speed-up over the default and
    the largest difference from the default's frequencies."""
    lines = ["What a looser `rtol` saves (`natural_frequencies(..., rtol=R)`): speed-up over the "
             "default of the same engine and kind of solve, every rtol timed in turn in each round "
             "(best of the rounds), so that a busy spell of the machine falls on all of them alike. "
             "The numpy engine is what a new process runs (`engine=\"auto\"` before the kernels are "
             "loaded); timed here, where the kernels are loaded, its coarse FE pencil is assembled "
             "compiled (the same numbers, a few ms faster than in a new process: "
             "`reports/speed_accuracy.md` times it there).", "",
             "| first N | rtol | compiled: first solve | speed-up | compiled: compiled model | speed-up | "
             "evaluations | numpy: first solve | speed-up | numpy: compiled model | speed-up | "
             "largest diff. from the default |", "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for count in counts:
        timed = interleaved_rtols(model, count, rounds)
        (cf0, ca0, reference), (nf0, na0, _) = timed[None, "compiled"], timed[None, "numpy"]
        for rtol in RTOLS:
            (cf, ca, result), (nf, na, _) = timed[rtol, "compiled"], timed[rtol, "numpy"]
            lines.append(f"| {count} | {'default' if rtol is None else f'{rtol:g}'} | {cf * 1e3:.1f} ms | "
                         f"{cf0 / cf:.2f}× | {ca * 1e3:.1f} ms | **{ca0 / ca:.2f}×** | {result.evaluations} | "
                         f"{nf * 1e3:.1f} ms | {nf0 / nf:.2f}× | {na * 1e3:.1f} ms | {na0 / na:.2f}× | "
                         f"{rel_diff(result.frequencies_hz, reference.frequencies_hz):.1e} |")
    return lines


def interleaved_rtols(model, count: int, rounds: int) -> dict:
    """{(rtol, engine): (best first solve s, best compiled-model solve s, result)} for each of
    RTOLS and both engines: in every round each is solved once for the first time
    (:func:`first_solve`'s way) and once again (:func:`solve_again`), in turn."""
    best = {}
    for _ in range(rounds):
        for rtol in RTOLS:
            options = {} if rtol is None else {"rtol": rtol}
            for engine in ("compiled", "numpy"):
                first, _ = first_solve(model, count, 1, engine, **options)
                start = time.perf_counter()
                result = solve_again(model, count, engine, **options)
                again = time.perf_counter() - start
                kept = best.get((rtol, engine), (np.inf, np.inf, None))
                best[rtol, engine] = (min(first, kept[0]), min(again, kept[1]), result)
    return best


#: Relative gaps between a steel cantilever's two bending planes (Iz = Iy (1 + gap)²) in the
#: table of close and multiple roots: 0 a symmetric section, every bending root double.
PLANE_GAPS = (0.0, 1e-7, 1e-6, 1e-5, 1e-3)
#: That cantilever: SI, 1.5 m long.
ROD = dict(E=2e11, G=8e10, rho=7800.0, A=1e-3, Iy=3e-7, J=2e-7, Ip=4.2e-7, L=1.5)


def rod(gap: float) -> Model:
    """:data:`ROD` clamped at x = 0, its Iz = Iy (1 + ``gap``)²."""
    r = ROD
    points = {"root": np.zeros(3), "tip": np.array([r["L"], 0.0, 0.0])}
    beam = Beam("rod", ("root", "tip"), r["E"], r["G"], r["rho"], r["A"], r["Iy"], r["Iy"] * (1 + gap) ** 2,
                r["J"], r["Ip"], np.eye(3), r["L"])
    return Model(f"rod, planes {gap:g} apart", points, beams=(beam,), boundary={"root": np.ones(6, dtype=bool)})


def close_roots_table(rounds: int) -> list[str]:
    """Markdown lines: evaluations and time of a first solve where the roots come in
    pairs (:func:`rod`, its bending planes PLANE_GAPS apart), against its closed form
    (:func:`common.cantilever_reference`: both planes, axial, torsion)."""
    lines = ["### Close and multiple roots", "",
             "A 1.5 m steel cantilever (`rod` in this script), its bending planes Iz = Iy (1 + gap)² apart: "
             "each bending root a pair that far apart, double for gap 0. First solve, compiled engine, "
             "default rtol (1e-9); error = largest |f / f_exact − 1| against the closed form.", "",
             "| gap | first N | first solve | evaluations | evaluations / root | error |",
             "|---:|---:|---:|---:|---:|---:|"]
    r, worst = ROD, 0.0
    for gap in PLANE_GAPS:
        model = rod(gap)
        for count in (10, 30):
            seconds, result = first_solve(model, count, rounds if count == 10 else 1)
            exact = np.array(cantilever_reference(r["E"], r["G"], r["rho"], r["A"], r["Iy"], r["Iy"] * (1 + gap) ** 2,
                                                  r["J"], r["Ip"], r["L"], count=count), dtype=float)
            error = np.max(np.abs(result.frequencies_hz / exact - 1))
            worst = max(worst, error)
            lines.append(f"| {gap:g} | {count} | {seconds * 1e3:.1f} ms | {result.evaluations} | "
                         f"{result.evaluations / count:.1f} | {error:.1e} |")
    verdict = ("every error is within the rtol of 1e-9" if worst <= 1e-9 else
               f"**the largest error, {worst:.1e}, is beyond the rtol of 1e-9: a defect**")
    return lines + ["", f"In this run {verdict}. A close pair is to come out as two roots, a double root as one of "
                        "multiplicity two (the Wittrick–Williams counts and the pencil's offsets decide which).", ""]


def count_costs(model, rounds: int) -> dict:
    """Seconds per Wittrick–Williams count J(ω) (the closing counts), compiled and numpy."""
    omegas = np.geomspace(1.0, 2e4, 64)
    costs = {}
    for name in ("compiled", "numpy"):
        counter, shifts = ModeCounter(model, name), iter(range(1, 10 ** 6))

        def counts():  # new frequencies each round: the counter remembers those it has answered
            shift = 1 + 1e-7 * next(shifts)
            return [counter(w * shift) for w in omegas]

        costs[name] = best_time(counts, rounds)[0] / omegas.size
    return costs


def rel_diff(a, b) -> float:
    n = min(len(a), len(b))
    return float(np.max(np.abs(np.asarray(a[:n]) / np.asarray(b[:n]) - 1))) if n else np.nan


def fe_eigensolves(model, count: int, target: np.ndarray, tolerance: float, rounds: int) -> dict:
    """The FE route's eigensolvers on the coarsest mesh within ``tolerance`` of ``target`` (Hz).

    Meshes of 1, 2, 4, … 128 elements per beam; each judged by shift-invert
    eigsh (dense eigh loses digits on fine meshes, whose beam-node masses are
    tiny). Where none is within ``tolerance``, the mesh that came closest.
    """
    shift = -0.5 * (2 * np.pi * target[0]) ** 2
    best = None
    for per_beam in (1, 2, 4, 8, 16, 32, 64, 128):
        fe = assemble(model, per_beam)
        K, M = fe.K.tocsc(), fe.M.tocsc()
        wanted = min(count + fe.rigid_modes.shape[1], K.shape[0] - 2)
        lam = np.sort(sla.eigsh(K, k=wanted, M=M, sigma=shift, which="LM", return_eigenvectors=False))
        error = rel_diff(np.sqrt(np.abs(lam[fe.rigid_modes.shape[1]:])) / (2 * np.pi), target)
        if best is None or error < best[0]:
            best = (error, per_beam, K, M, wanted)
        if error <= tolerance:
            break
    error, per_beam, K, M, wanted = best
    eigsh_time = best_time(lambda: sla.eigsh(K, k=wanted, M=M, sigma=shift, which="LM",
                                             return_eigenvectors=False), rounds)[0]
    eigh_time = np.nan
    if K.shape[0] <= DENSE_LIMIT:
        dense_K, dense_M = K.toarray(), M.toarray()
        eigh_time = best_time(lambda: la.eigh(dense_K, dense_M, eigvals_only=True,
                                              subset_by_index=[0, wanted - 1]), rounds)[0]
    return {"per_beam": per_beam, "dof": K.shape[0], "error": error, "eigh": eigh_time, "eigsh": eigsh_time}


def shapes_table(model, meshes: dict, rounds: int) -> list[str]:
    """Markdown lines: ``mode_shapes`` (21 stations per beam, mass-normalised) by both engines
    on a model compiled already, beside FE shift-invert ``eigsh`` with its eigenvectors on
    the mesh of the frequency table (``meshes``: first N -> (elements per beam, the lowest
    frequency Hz, which places eigsh's shift as :func:`fe_eigensolves` places it)), assembly
    excluded, best of ``rounds`` each."""
    lines = ["Mode shapes: `mode_shapes(model, N)` (21 stations per beam, mass-normalised; the model "
             "compiled already, its predictions kept) against FE `eigsh` returning its eigenvectors on the "
             "mesh of the first table (assembly excluded). The numpy engine forms det Ū_all, the counts and "
             "the shapes' Ū_all by the numpy carry; `linmstmm modes` runs it in a new process, where the "
             "coarse FE pencil is assembled without the kernels this process has loaded (the same numbers, "
             "a few ms slower).", "",
             "| first N | MSTMM compiled | MSTMM numpy | FE eigsh with vectors | FE / MSTMM compiled |",
             "|---:|---:|---:|---:|---:|"]
    for count, (per_beam, first) in meshes.items():
        compiled = best_time(lambda: mode_shapes(model, count, engine="compiled"), rounds)[0]
        numpy_engine = best_time(lambda: mode_shapes(model, count, engine="numpy"), rounds)[0]
        fe = assemble(model, per_beam)
        K, M = fe.K.tocsc(), fe.M.tocsc()
        wanted = min(count + fe.rigid_modes.shape[1], K.shape[0] - 2)
        eigsh = best_time(lambda: sla.eigsh(K, k=wanted, M=M, sigma=-0.5 * (2 * np.pi * first) ** 2, which="LM"),
                          rounds)[0]
        lines.append(f"| {count} | {compiled * 1e3:.1f} ms | {numpy_engine * 1e3:.1f} ms | {eigsh * 1e3:.1f} ms "
                     f"({per_beam} el./beam) | {eigsh / compiled:.2f} |")
    return lines


def budget_table(model, counts) -> list[str]:
    """Markdown lines: where the first solve of ``model`` for each count spends its time
    and evaluations (its compilation included)."""
    budgets = {}
    for count in counts:
        forget_compiled_models()
        budgets[count] = time_budget(lambda: natural_frequencies(model, count, engine="compiled"))[1]
    stages = [name for name in budgets[counts[0]] if any(b[name][0] > 1e-4 or b[name][1] for b in budgets.values())]
    lines = ["Where the first solve of a model spends its time (`benchmarks/time_budget.py`: "
             "stages timed exclusively, each evaluation of det Ū_all charged to the stage that asked for "
             "it). The stages from *topology* to the counter's build compile the model "
             "(`linmstmm/compiled_model.py`; so does the coarse FE pencil's assembly in *predict*) "
             "and are not made again when the same model object is solved again:", "",
             "| stage | " + " | ".join(f"first {count}: ms (evaluations)" for count in counts) + " |",
             "|---|" + "---:|" * len(counts)]
    for name in stages:
        lines.append(f"| {name} | " + " | ".join(
            f"{budgets[c][name][0] * 1e3:.1f} ({budgets[c][name][1]})" for c in counts) + " |")
    lines.append("| **total** | " + " | ".join(
        f"**{sum(v[0] for v in budgets[c].values()) * 1e3:.1f}** ({sum(v[1] for v in budgets[c].values())})"
        for c in counts) + " |")
    return lines


def startup(command: list[str], rounds: int) -> float:
    """Median wall time of a new process running ``command`` (s)."""
    times = []
    for _ in range(rounds + 1):
        start = time.perf_counter()
        subprocess.run(command, cwd=REPO, capture_output=True, check=True)
        times.append(time.perf_counter() - start)
    return float(np.median(times[1:]))


#: Beam elements of the cantilever whose new-process solve :func:`large_model_rows` times.
LARGE_CANTILEVER = 1000


def large_model_rows() -> list[str]:
    """Rows of the new-process table: the first 20 frequencies of a cantilever of
    LARGE_CANTILEVER beam elements (a model file written for it), by the default engine,
    which loads the kernels for a request that large (linmstmm.determinant.kernels_pay),
    and by the numpy carry; median of three processes each."""
    with tempfile.TemporaryDirectory() as folder:
        path = beam_chain_file(LARGE_CANTILEVER, Path(folder))
        command = [sys.executable, "-m", "linmstmm", "freqs", str(path), "--count", "20", "--quiet"]
        return [f"| `linmstmm freqs` on a cantilever of {LARGE_CANTILEVER:,} beam elements (a model file), "
                f"first 20 (engine auto: the kernels loaded for a request that large) | {startup(command, 2):.2f} s |",
                f"| the same with `--engine numpy` | {startup(command + ['--engine', 'numpy'], 2):.2f} s |"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="counts 10 and 20 only, fewer rounds")
    parser.add_argument("--out", type=Path, default=None, help="folder for speed.md and figures/ "
                        "(default reports/, or a temporary folder with --quick)")
    args = parser.parse_args()
    out = args.out or (Path(tempfile.mkdtemp()) if args.quick else REPO / "reports")
    counts = (10, 20) if args.quick else (10, 20, 60, 100)
    rounds = 2 if args.quick else 5
    started = time.perf_counter()
    load_kernels()
    lines = ["# Speed of the transfer-matrix solve against the FE route",
             "",
             f"Generated by `python benchmarks/bench_speed.py{' --quick' if args.quick else ''}` "
             f"on {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC. Every number below is from that one run "
             "(best of several calls in one process, kernels loaded; a second core busy with other work "
             "inflates times, ratios much less). BLAS at one thread for both routes (`linmstmm.threads`). "
             "*MSTMM, first solve*: a model solved for the first time, its compilation included "
             "(`linmstmm/compiled_model.py`: what a new process or a new model pays). *MSTMM, compiled "
             "model*: the same model object solved again, which only predicts (the coarse eigensolve), "
             "evaluates, polishes and counts, afresh: the counterpart of the FE eigensolver times, which exclude assembly. The ratio "
             "column gives the fastest FE eigensolver over the compiled-model solve, and in brackets over "
             "the first solve.", ""]
    curves = {}
    with one_blas_thread():
        for label, path in MODELS.items():
            if not path.exists():
                continue
            model = load_model(path)
            costs = evaluation_costs(model, rounds)
            lines += [f"## {label}", "",
                      f"| one evaluation of det Ū_all | single ω | per ω in a batch of 512, one thread | "
                      f"per ω in a batch of 512, {spread.cores()} cores |", "|---|---:|---:|---:|",
                      *[f"| {name} | {single * 1e6:.0f} µs | {batch * 1e6:.0f} µs | "
                        + (f"{shared * 1e6:.0f} µs |" if np.isfinite(shared) else "- |")
                        for name, (single, batch, shared) in costs.items()], "",
                      "| one Wittrick–Williams count J(ω) (one real LDLᵀ, twice) | single ω |", "|---|---:|",
                      *[f"| {name} | {seconds * 1e6:.0f} µs |" for name, seconds in count_costs(model, rounds).items()],
                      "",
                      "| first N | MSTMM, first solve | MSTMM, compiled model | evaluations / root | "
                      "diff. from FE rtol 1e-10 | FE mesh (el./beam, DOF) | its diff. from MSTMM | FE dense eigh | "
                      "FE eigsh | `fe` command | fastest FE eigensolver / MSTMM compiled (first) | "
                      "`fe` / MSTMM first solve |",
                      "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
            asked_lines, meshes = [], {}
            for count in counts:
                repeats = rounds if count <= 20 else 1
                first_time, asked_first, fe_time, asked = first_solves_beside_fe(model, count, repeats + 1)
                mstmm_time, result = best_time(lambda: solve_again(model, count), repeats)
                fe_result = fe_frequencies(model, count, rtol=1e-10)  # the reference, not timed
                tolerance = 1e-9 if count < 60 else 1e-6
                solves = fe_eigensolves(model, count, result.frequencies_hz, tolerance, repeats)
                per_root = result.evaluations / max(len(result.frequencies_hz), 1)
                fastest = np.nanmin([solves.get("eigh", np.nan), solves.get("eigsh", np.nan)])
                meshes[count] = solves.get("per_beam"), result.frequencies_hz[0]
                lines.append(
                    f"| {count} | {first_time * 1e3:.1f} ms | {mstmm_time * 1e3:.1f} ms | {per_root:.1f} | "
                    f"{rel_diff(result.frequencies_hz, fe_result.frequencies_hz):.1e} | "
                    f"{solves.get('per_beam', '-')}, {solves.get('dof', '-')} | {solves.get('error', np.nan):.1e} | "
                    f"{solves.get('eigh', np.nan) * 1e3:.1f} ms | {solves.get('eigsh', np.nan) * 1e3:.1f} ms | "
                    f"{fe_time * 1e3:.0f} ms | **{fastest / mstmm_time:.2f}** ({fastest / first_time:.2f}) | "
                    f"{fe_time / first_time:.1f} |")
                asked_time, _ = best_time(lambda: solve_again(model, count, rtol=ASKED_RTOL), repeats)
                asked_lines.append(
                    f"| {count} | {asked_first * 1e3:.1f} ms | {asked_time * 1e3:.1f} ms | "
                    f"{asked.evaluations / max(len(asked.frequencies_hz), 1):.1f} | "
                    f"{rel_diff(asked.frequencies_hz, result.frequencies_hz):.1e} | "
                    f"{rel_diff(asked.frequencies_hz, fe_result.frequencies_hz):.1e} | "
                    f"**{fastest / asked_time:.2f}** ({fastest / asked_first:.2f}) | {fe_time / asked_first:.1f} |")
                curves.setdefault(label, []).append((count, first_time, mstmm_time, solves.get("eigh", np.nan),
                                                     solves.get("eigsh", np.nan), fe_time, asked_first))
            lines += ["", f"The same, certified to {ASKED_RTOL:g} as asked for (`rtol={ASKED_RTOL:g}`): a lone "
                      "prediction that the Wittrick–Williams counts at ±rtol certify is listed as it stands, "
                      "unpolished; the default polishes every root to rounding. The FE mesh and times are "
                      "those of the table above.", "",
                      "| first N | MSTMM, first solve | MSTMM, compiled model | evaluations / root | "
                      "diff. from the default | diff. from FE rtol 1e-10 | fastest FE eigensolver / MSTMM "
                      "compiled (first) | `fe` / MSTMM first solve |", "|---:|---:|---:|---:|---:|---:|---:|---:|",
                      *asked_lines]
            lines += ["", *budget_table(model, counts), "", *rtol_table(model, counts[:2], 2 * rounds), "",
                      *shapes_table(model, {c: meshes[c] for c in counts[:2]}, rounds), ""]
        lines += ["## Beyond the launchers", "", *close_roots_table(rounds)]
    lines += ["**Reading the FE columns.** The FE mesh is the coarsest of 1, 2, 4, … 128 elements per "
              "beam whose first N frequencies by eigsh are within 1e-9 of the transfer-matrix ones (1e-6 "
              "from N = 60), or, where none is, the mesh that came closest (column *its diff. from "
              "MSTMM*): refining further makes the fixed-mesh eigenproblem worse, not better, as its "
              "beam-node masses shrink. The eigensolver times exclude assembly, which the `fe` command's "
              "refinement with Richardson extrapolation includes. The `fe` command column is "
              "`fe_frequencies` at its defaults (rtol 1e-9, as the command runs), timed in turn with the "
              "MSTMM first solves in every round, best of the rounds; its run at rtol 1e-10 is the "
              "reference of the *diff.* columns and is not timed.", ""]
    command = [sys.executable, "-m", "linmstmm", "freqs", "models/mlrs/mlrs.toml"]
    lines += ["## New processes: start-up and modal response", "",
              "| command | median wall time |", "|---|---:|",
              f"| `linmstmm freqs models/mlrs/mlrs.toml` (engine auto: numpy in a new process) | "
              f"{startup(command, rounds):.2f} s |",
              f"| the same with `--engine compiled` (numba import and cached kernels) | "
              f"{startup(command + ['--engine', 'compiled'], rounds):.2f} s |",
              *[f"| `linmstmm response {model} {loads}` (the bundled load case; BLAS threads as the "
                f"machine sets them) | {startup([sys.executable, '-m', 'linmstmm', 'response', model, loads], rounds):.2f} s |"
                for model, loads in RESPONSE_CASES],
              *large_model_rows(), ""]
    figure = draw(curves, out / "figures" / "speed_vs_fe.png")
    lines += [f"![time against the number of frequencies]({figure.relative_to(out).as_posix()})", "",
              "*Wall time against the number of frequencies asked for, both launcher models; "
              "FE eigensolvers on the mesh of the tables (assembly excluded).*", "",
              f"Run time of this script: {time.perf_counter() - started:.0f} s."]
    (out / "speed.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    print(out / "speed.md")


def draw(curves: dict, path: Path) -> Path:
    """Log-log wall time against the count, one panel per model."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path.parent.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, max(len(curves), 1), figsize=(6 * max(len(curves), 1), 4.2), squeeze=False)
    styles = [("MSTMM, first solve (model compiled in it)", "o-", 1),
              ("MSTMM, compiled model (compilation excluded)", "o--", 2),
              ("FE dense eigh (assembly excluded)", "s--", 3),
              ("FE eigsh (assembly excluded)", "^:", 4), ("fe command (refinement)", "d-.", 5),
              (f"MSTMM, first solve, rtol={ASKED_RTOL:g}", "v-", 6)]
    for ax, (label, rows) in zip(axes[0], curves.items()):
        rows = np.array(rows, dtype=float)
        for name, style, column in styles:
            ax.loglog(rows[:, 0], rows[:, column] * 1e3, style, label=name)
        ax.set_xticks(rows[:, 0], [f"{int(c)}" for c in rows[:, 0]])
        ax.minorticks_off()
        ax.set_xlabel("natural frequencies asked for")
        ax.set_ylabel("wall time, ms")
        ax.set_title(label, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


if __name__ == "__main__":
    main()
