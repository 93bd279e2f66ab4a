"""Cost against size: spring–mass chains (and beam chains) of N elements.

    python benchmarks/bench_chain.py [N ...] [--beams] [--count 20] [--no-fe]

For each N: topology + deduction build, one stable determinant evaluation
(Deduction.log_det) per frequency in a batch of 64 and for a single
frequency, the full MSTMM solve of the first ``count`` frequencies and the
FE route's (springs: exact assembly; beams: one element per beam, the same
element count, without refinement), each with its max relative error
against the closed form. Not part of the test suite.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from common import (beam_chain, beam_chain_reference_hz, best_of, max_relative_error, spring_chain,
                    spring_chain_reference_hz)

from linmstmm.deduction import Deduction
from linmstmm.fe import fe_frequencies
from linmstmm.solve import natural_frequencies
from linmstmm.topology import build_topology


def measure(n: int, beams: bool, count: int, fe: bool) -> dict:
    """Timings (s) and errors for one chain of ``n`` elements per kind."""
    model = beam_chain(n) if beams else spring_chain(n)
    reference = np.array([float(f) for f in beam_chain_reference_hz(count)]) if beams \
        else spring_chain_reference_hz(n, count)
    start = time.perf_counter()
    deduction = Deduction(build_topology(model))
    out = {"n": n, "build": time.perf_counter() - start}
    omega = 2 * np.pi * np.geomspace(reference[0] / 2, reference[-1] * 1.2, 64)
    out["det_batch"] = best_of(lambda: deduction.log_det(omega), 3, 1.0)[0] / omega.size
    out["det_single"] = best_of(lambda: deduction.log_det(omega[:1]), 5, 1.0)[0]
    seconds, result, *_ = best_of(lambda: natural_frequencies(model, count), 3, 2.0)
    out["solve"], out["solve_error"] = seconds, max_relative_error(result.frequencies_hz, reference)
    if fe:
        options = dict(elements_per_beam=1, estimate_error=False) if beams else {}
        seconds, result, *_ = best_of(lambda: fe_frequencies(model, count, **options), 3, 2.0)
        out["fe"], out["fe_error"] = seconds, max_relative_error(result.frequencies_hz, reference)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", type=int, nargs="*", default=[10, 100, 1000])
    parser.add_argument("--beams", action="store_true", help="beam chains instead of spring–mass chains")
    parser.add_argument("--count", type=int, default=20)
    parser.add_argument("--no-fe", action="store_true")
    args = parser.parse_args()
    kind = "beam elements" if args.beams else "bodies (+ as many springs)"
    print(f"chains of N {kind}; first {args.count} frequencies; times in ms")
    print(f"{'N':>6} {'build':>9} {'det/64':>9} {'det 1':>9} {'solve':>10} {'err':>8} {'FE':>10} {'FE err':>8}")
    for n in args.sizes:
        r = measure(n, args.beams, args.count, not args.no_fe)
        fe = f"{r['fe'] * 1e3:10.1f} {r['fe_error']:8.1e}" if "fe" in r else ""
        print(f"{n:6d} {r['build'] * 1e3:9.2f} {r['det_batch'] * 1e3:9.3f} {r['det_single'] * 1e3:9.3f} "
              f"{r['solve'] * 1e3:10.1f} {r['solve_error']:8.1e} {fe}", flush=True)


if __name__ == "__main__":
    main()
