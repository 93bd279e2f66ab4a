"""MLRS-style launcher, first ten frequencies: MSTMM against the FE route, side by side.

    python benchmarks/bench_mlrs.py [--rounds 5] [--reference]

Prints the best wall time of each route over interleaved rounds (the FE route
also with OpenBLAS limited to one thread at run time), the ratios,
and (with --reference, ~25 s more) the achieved max relative error against
``natural_frequencies(..., digits=25)``; without it the routes are compared
with each other only. Not part of the test suite.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from common import REPO, blas_threads, max_relative_error

from linmstmm.compiled_model import forget_compiled_models
from linmstmm.fe import fe_frequencies
from linmstmm.model import load_model
from linmstmm.solve import natural_frequencies

MODEL = REPO / "models" / "mlrs" / "mlrs.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--count", type=int, default=10)
    parser.add_argument("--reference", action="store_true", help="also solve at 25 digits (slow)")
    args = parser.parse_args()

    model = load_model(MODEL)
    def fe_one_thread():
        with blas_threads(1):  # at run time; no environment variable is changed
            return fe_frequencies(model, args.count).frequencies_hz

    routes = {
        "MSTMM natural_frequencies()": lambda: natural_frequencies(model, args.count).frequencies_hz,
        "FE automatic refinement, rtol=1e-9": lambda: fe_frequencies(model, args.count).frequencies_hz,
        "FE automatic refinement, BLAS 1 thread": fe_one_thread,
    }
    best = {name: np.inf for name in routes}
    result = {}
    for name, route in routes.items():  # warm-up (imports, caches)
        result[name] = route()
    for _ in range(args.rounds):
        for name, route in routes.items():
            forget_compiled_models()  # each MSTMM run a first solve, as each FE run assembles anew
            start = time.perf_counter()
            result[name] = route()
            best[name] = min(best[name], time.perf_counter() - start)

    reference = None
    if args.reference:
        reference = natural_frequencies(model, args.count, digits=25).frequencies_hz
    print(f"{MODEL.relative_to(REPO)}: first {args.count} frequencies, best of {args.rounds} interleaved rounds")
    for name in routes:
        error = "" if reference is None else f"  max rel error {max_relative_error(result[name], reference):.2e}"
        print(f"  {name:38s} {best[name] * 1e3:9.1f} ms{error}")
    names = list(routes)
    for name in names[1:]:
        print(f"  {name} / MSTMM time ratio: {best[name] / best[names[0]]:.2f}")
    print(f"  routes agree to {max_relative_error(result[names[0]], result[names[1]]):.2e} (max rel difference)")
    print("  frequencies, Hz:", np.array2string(result[names[0]], precision=6))


if __name__ == "__main__":
    main()
