"""Shared pieces of the benchmarks and of ``scripts/speed_accuracy.py``.

Not part of the test suite. Everything here is independent of the transfer
matrices except :func:`mstmm_solve`, which runs the MSTMM pipeline of
:func:`linmstmm.solve.natural_frequencies` with the user-visible root-finder
settings made explicit.

* model builders: a uniform spring–mass chain (ground–k–m–k–m–…, point
  masses, isotropic translational springs, rotations locked), and a uniform
  steel cantilever cut into N equal beam elements;
* closed-form references in mpmath: the cantilever with a point tip mass
  (bending in both planes, axial, torsion) and the fixed–free chain;
* timing and error helpers.
"""
from __future__ import annotations

import inspect
import sys
import time
from pathlib import Path

import mpmath as mp
import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from linmstmm.builders import spring_chain  # noqa: E402,F401  (the chains of the benchmarks)
from linmstmm.model import Beam, Model  # noqa: E402
from linmstmm.roots import RootFinder  # noqa: E402

STEEL = dict(E=2.1e11, G=8.1e10, rho=7850.0)


# --------------------------------------------------------------------------
# timing and errors

def best_of(function, repeats: int = 5, budget: float = 2.0, compiled: bool = False):
    """Run ``function()`` up to ``repeats`` times (at least once), stopping
    early once ``budget`` seconds have been spent. Returns (best wall time s,
    last result, runs made, best process CPU time s).

    Every run is a first solve (the models compiled by an earlier run are
    forgotten before it, untimed: :func:`linmstmm.compiled_model.forget_compiled_models`),
    as a new process's would be; ``compiled=True`` keeps them, to time solves of
    models already compiled."""
    from linmstmm.compiled_model import forget_compiled_models

    best, best_cpu, result, runs, spent = np.inf, np.inf, None, 0, 0.0
    while runs < repeats and (runs == 0 or spent < budget):
        if not compiled:
            forget_compiled_models()
        start, cpu = time.perf_counter(), time.process_time()
        result = function()
        elapsed = time.perf_counter() - start
        best_cpu = min(best_cpu, time.process_time() - cpu)
        best, spent, runs = min(best, elapsed), spent + elapsed, runs + 1
    return best, result, runs, best_cpu


def _openblas_libraries():
    """ctypes handles of every OpenBLAS loaded in this process (numpy's and scipy's), with their
    (get_num_threads, set_num_threads, get_corename) functions."""
    import ctypes
    np.linalg.qr(np.eye(3))
    import scipy.linalg
    scipy.linalg.qr(np.eye(3))
    paths = sorted({line.split()[-1] for line in open("/proc/self/maps")
                    if "openblas" in line.lower() and line.split()[-1].endswith(".so")})
    found = []
    for path in paths:
        lib = ctypes.CDLL(path)
        for prefix in ("scipy_openblas", "openblas"):
            for suffix in ("64_", ""):
                get = getattr(lib, f"{prefix}_get_num_threads{suffix}", None)
                put = getattr(lib, f"{prefix}_set_num_threads{suffix}", None)
                core = getattr(lib, f"{prefix}_get_corename{suffix}", None)
                if get and put:
                    if core:
                        core.restype = ctypes.c_char_p
                    found.append((path, get, put, core))
                    break
            else:
                continue
            break
    return found


class blas_threads:
    """Context manager: every loaded OpenBLAS limited to ``n`` threads at run time
    (no environment variable is touched), restored on exit."""

    def __init__(self, n: int):
        self.n = n
        self.saved = []

    def __enter__(self):
        try:
            for _, get, put, _ in _openblas_libraries():
                self.saved.append((put, get()))
                put(self.n)
        except OSError:
            pass
        return self

    def __exit__(self, *exc):
        for put, n in self.saved:
            put(n)


def max_relative_error(got, reference) -> float:
    """max |got_i / ref_i − 1| over the reference's entries; inf if fewer were found."""
    got = np.asarray(got, dtype=float)
    reference = np.asarray([float(r) for r in reference])
    if got.size < reference.size:
        return np.inf
    return float(np.max(np.abs(got[:reference.size] / reference - 1.0)))


# --------------------------------------------------------------------------
# the MSTMM pipeline with explicit settings

def root_finder_defaults() -> dict:
    """RootFinder's default xtol, points_per_octave, points_per_root (read from its signature)."""
    parameters = inspect.signature(RootFinder.__init__).parameters
    return {name: parameters[name].default for name in ("xtol", "points_per_octave", "points_per_root")}


def mstmm_solve(model: Model, count: int, **options) -> np.ndarray:
    """Lowest ``count`` elastic frequencies (Hz) by the float64 MSTMM pipeline.

    The same steps as ``natural_frequencies`` (topology, deduction, release of
    indeterminate unknowns, rigid-body count, root search) with the
    RootFinder options (xtol, points_per_octave, points_per_root) given
    explicitly, and no mpmath escalation: a loose ``xtol`` would otherwise
    send every root to mpmath (natural_frequencies refines every root whose
    last Newton step exceeds CERTIFIED_STEP = 1e-9), which is the opposite
    of what a user loosening the tolerance asks for.
    """
    try:
        from linmstmm.solve import frequency_finder
        _, finder, _ = frequency_finder(model, **options)
    except ImportError:  # older tree: build it like solve.py does
        from linmstmm.deduction import Deduction
        from linmstmm.nullspace import release_indeterminate
        from linmstmm.topology import build_topology
        deduction = Deduction(build_topology(model))
        release_indeterminate(deduction)
        finder = RootFinder(deduction.log_det, lambda w: deduction.matrix(w, stable=True)[0], **options)
    return finder.find(count, None).roots / (2 * np.pi)


# --------------------------------------------------------------------------
# models

def spring_chain_reference_hz(n: int, count: int, m: float = 1.0, k: float = 1e6) -> np.ndarray:
    """Lowest ``count`` frequencies of :func:`linmstmm.builders.spring_chain` (each triple), closed form:
    ω_j = 2 √(k/m) sin((2j − 1) π / (2 (2N + 1)))."""
    j = np.arange(1, count // 3 + 2)
    omega = 2 * np.sqrt(k / m) * np.sin((2 * j - 1) * np.pi / (2 * (2 * n + 1)))
    return np.repeat(omega / (2 * np.pi), 3)[:count]


#: Section of the beam chain (Iy ≠ Iz: the two bending planes differ).
BEAM_CHAIN_SECTION = dict(A=1e-3, Iy=2e-7, Iz=3e-7, J=4e-7, Ip=5e-7)


def beam_chain(n: int, length: float = 2.0) -> Model:
    """A steel cantilever of ``length`` along x cut into ``n`` equal beam elements (fixed at x = 0)."""
    s = BEAM_CHAIN_SECTION
    points = {f"p{i}": np.array([length * i / n, 0.0, 0.0]) for i in range(n + 1)}
    beams = tuple(Beam(f"b{i}", (f"p{i}", f"p{i + 1}"), STEEL["E"], STEEL["G"], STEEL["rho"],
                       s["A"], s["Iy"], s["Iz"], s["J"], s["Ip"], np.eye(3), length / n)
                  for i in range(n))
    return Model(f"beam chain N={n}", points, beams=beams, boundary={"p0": np.ones(6, dtype=bool)})


def beam_chain_file(n: int, folder: Path, length: float = 2.0, round_section: bool = False) -> Path:
    """:func:`beam_chain` written as a model file ``folder``/beam_chain_<n>.toml, for a new
    process's command to read (the same model, but for the rounding of the beams' lengths,
    which the loader takes from the points); with ``round_section``, Iz = Iy (every bending
    frequency double), as ``folder``/round_chain_<n>.toml."""
    s = dict(BEAM_CHAIN_SECTION, Iz=BEAM_CHAIN_SECTION["Iy"]) if round_section else BEAM_CHAIN_SECTION
    lines = [f'name = "beam chain N={n}"', "", "[points]"]
    lines += [f"p{i} = [{length * i / n!r}, 0.0, 0.0]" for i in range(n + 1)]
    for i in range(n):
        lines += ["", "[[beam]]", f'name = "b{i}"', f'ends = ["p{i}", "p{i + 1}"]',
                  *(f"{key} = {value!r}" for key, value in (("E", STEEL["E"]), ("G", STEEL["G"]),
                                                           ("rho", STEEL["rho"]), *s.items()))]
    lines += ["", "[boundary]", 'p0 = "fixed"']
    path = folder / f"{'round' if round_section else 'beam'}_chain_{n}.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def cantilever_reference(E, G, rho, A, Iy, Iz, J, Ip, L, tip_mass=0.0, count=10, dps=30):
    """Lowest ``count`` natural frequencies (Hz, mpf, ascending) of a uniform
    Euler–Bernoulli cantilever with a point tip mass (no rotary inertia).

    Closed-form frequency equations, roots in mpmath at ``dps`` digits:
    * bending, each plane: 1 + cos λ cosh λ + μ λ (cos λ sinh λ − sin λ cosh λ) = 0,
      μ = M / (ρ A L), ω = λ² √(E I / (ρ A L⁴)) — written divided by cosh λ;
    * axial: κ tan κ = ρ A L / M (κ = (2j−1)π/2 without a tip mass), ω = κ/L √(E/ρ);
    * torsion (the point mass adds no polar inertia): ω = (2j−1)π/(2L) √(G J / (ρ Ip)).
    """
    with mp.workdps(dps + 10):
        E, G, rho, A, L, M = (mp.mpf(v) for v in (E, G, rho, A, L, tip_mass))
        mu = M / (rho * A * L)

        def bending(lam):
            return 1 / mp.cosh(lam) + mp.cos(lam) + mu * lam * (mp.cos(lam) * mp.tanh(lam) - mp.sin(lam))

        def axial(kappa):
            return mp.cos(kappa) * rho * A * L - M * kappa * mp.sin(kappa)

        def roots(function, how_many, step=mp.mpf("0.05")):
            found, x, value = [], mp.mpf("1e-6"), function(mp.mpf("1e-6"))
            while len(found) < how_many:
                y = x + step
                new = function(y)
                if value * new < 0:
                    found.append(mp.findroot(function, (x, y), solver="anderson"))
                x, value = y, new
            return found

        out = []
        for inertia in (Iy, Iz):
            scale = mp.sqrt(E * mp.mpf(inertia) / (rho * A * L**4))
            out += [lam**2 * scale for lam in roots(bending, count)]
        axial_roots = roots(axial, count) if M > 0 else [(2 * j - 1) * mp.pi / 2 for j in range(1, count + 1)]
        out += [kappa / L * mp.sqrt(E / rho) for kappa in axial_roots]
        out += [(2 * j - 1) * mp.pi / (2 * L) * mp.sqrt(G * mp.mpf(J) / (rho * mp.mpf(Ip)))
                for j in range(1, count + 1)]
        return sorted(w / (2 * mp.pi) for w in out)[:count]


def beam_chain_reference_hz(count: int, length: float = 2.0, dps: int = 30) -> list:
    """Closed-form lowest ``count`` frequencies (Hz, mpf) of :func:`beam_chain` (any N)."""
    return cantilever_reference(STEEL["E"], STEEL["G"], STEEL["rho"], L=length, count=count, dps=dps,
                                **BEAM_CHAIN_SECTION)


def machine_facts() -> dict:
    """CPU, cores, BLAS library, its thread count and kernel, OPENBLAS_* variables."""
    import os
    import platform

    import scipy
    facts = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
             "mpmath": mp.__version__, "cores": os.cpu_count()}
    try:
        facts["cpu"] = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo")
                            if line.startswith("model name"))
    except (OSError, StopIteration):
        facts["cpu"] = platform.processor() or "?"
    facts["env"] = {k: v for k, v in sorted(os.environ.items())
                    if k.startswith(("OPENBLAS", "OMP_", "MKL_", "BLIS"))}
    try:  # the OpenBLAS builds loaded (numpy's and scipy's): thread count and the kernel each runs
        facts["blas"] = "; ".join(
            f"{Path(path).name}: {get()} threads, kernel {core().decode() if core else '?'}"
            for path, get, _, core in _openblas_libraries())
    except OSError:
        pass
    facts.setdefault("blas", "unknown")
    return facts
