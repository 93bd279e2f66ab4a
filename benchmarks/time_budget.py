"""Where the time of one ``natural_frequencies`` call goes: stage by stage, with evaluations.

``time_budget(call)`` runs ``call()`` once with the pipeline's stages wrapped
in timers (exclusive time: a stage called inside another is subtracted from
it) and every evaluation of det Ū_all charged to the innermost stage running.
The stages up to the counter's build are the model's compilation
(:mod:`linmstmm.compiled_model`), made on a model object's first solve only.
Used by ``benchmarks/bench_speed.py``; nothing in the package depends on it.
"""
from __future__ import annotations

import time
from contextlib import contextmanager

import linmstmm.determinant as determinant_module
from linmstmm import compiled_model, predicted, roots, solve
from linmstmm.roots import finder

#: (module or class, attribute, stage name), in pipeline order.
STAGES = (
    (compiled_model, "build_topology", "topology"),
    (compiled_model, "Deduction", "deduction"),
    (compiled_model, "determinant", "compile the program"),
    (compiled_model, "release_indeterminate", "indeterminate unknowns (probes)"),
    (compiled_model, "rigid_body_mode_count", "rigid-body count"),
    (compiled_model, "count_in_disc", "rigid-body zeros (disc count)"),
    (compiled_model, "mode_counter", "Wittrick–Williams counter (build)"),
    (solve, "predicted_modes", "predict (coarse FE)"),
    (finder, "refined_predictions", "refine (Rayleigh functional)"),
    (predicted, "secant_roots", "polish (secant)"),
    (roots.RootFinder, "polish", "polish (pencil)"),
    (roots.RootFinder, "segment", "segment search"),
    (roots.RootFinder, "other_zeros", "certify (counts)"),
    (solve, "_refined_in_mpmath", "mpmath refinement"),
)
EVALUATORS = ((determinant_module.CompiledDeterminant, "_evaluate"),
              (determinant_module.NumpyDeterminant, "log_det"),
              (determinant_module.NumpyDeterminant, "matrix"))


@contextmanager
def _patched(target, name: str, replacement):
    original = getattr(target, name)
    setattr(target, name, replacement(original))
    try:
        yield
    finally:
        setattr(target, name, original)


def time_budget(call) -> tuple[object, dict]:
    """(``call()``'s result, {stage: [seconds, evaluations]}) with "other" for the rest."""
    totals: dict[str, list] = {name: [0.0, 0] for *_, name in STAGES}
    totals["other"] = [0.0, 0]
    stack: list[list] = []  # [name, start, time of the stages inside]

    def timed(name):
        def wrap(original):
            def run(*args, **kwargs):
                stack.append([name, time.perf_counter(), 0.0])
                try:
                    return original(*args, **kwargs)
                finally:
                    _, start, inner = stack.pop()
                    elapsed = time.perf_counter() - start
                    totals[name][0] += elapsed - inner
                    if stack:
                        stack[-1][2] += elapsed
            return run
        return wrap

    def counted(original):
        def run(self, omega, *args, **kwargs):
            size = getattr(omega, "size", 1)
            totals[stack[-1][0] if stack else "other"][1] += size
            return original(self, omega, *args, **kwargs)
        return run

    patches = [(_patched(t, attr, timed(name))) for t, attr, name in STAGES]
    patches += [_patched(t, attr, counted) for t, attr in EVALUATORS]
    start = time.perf_counter()
    for patch in patches:
        patch.__enter__()
    try:
        result = call()
    finally:
        for patch in reversed(patches):
            patch.__exit__(None, None, None)
    total = time.perf_counter() - start
    totals["other"][0] = total - sum(seconds for seconds, _ in totals.values())
    return result, totals
