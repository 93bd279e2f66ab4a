"""Random models against the FE route: a sweep over many random models and kinds.

    python benchmarks/sweep_vs_fe.py --modes 80 --seeds 0 32 [--kinds ring loops] [--digits 20]

For each seed and kind of ``tests/random_models.py`` it solves the lowest
``--modes`` frequencies with ``natural_frequencies`` and with ``fe_frequencies``
(automatic refinement, rtol 1e-9) and prints one line per model: the wall times,
the precision MSTMM used, and what differs:

* ``DISAGREE``: differs by more than AGREEMENT where FE's own error estimate is
  below TRUSTED (a defect of one of the two routes: look at it);
* ``fe-untrusted``: differs where FE's estimate is above TRUSTED (FE stopped at
  its mesh cap; finer fixed meshes decide, see ``test_random_systems.py``);
* ``LEN``: a different number of frequencies; ``NOTE``: MSTMM's note;
  ``MSTMM ERROR`` / ``FE ERROR``: the exception.

A summary follows. Not part of the test suite (80 modes: about 6 s a model).
"""
from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from common import REPO

sys.path.insert(0, str(REPO / "tests"))
from random_models import KINDS, random_model  # noqa: E402

from linmstmm.fe import fe_frequencies  # noqa: E402
from linmstmm.solve import natural_frequencies  # noqa: E402

#: Relative difference that counts as disagreement.
AGREEMENT = 1e-7
#: FE frequencies whose own error estimate is below this are a reference.
TRUSTED = 1e-8


def compare(kind: str, seed: int, modes: int, digits: int | None = None) -> tuple[str, str]:
    """(verdict, line) for one random model: verdict is "ok", "disagree", "untrusted"
    or "error"."""
    model = random_model(kind, seed)
    started = time.perf_counter()
    try:
        result = natural_frequencies(model, modes, digits=digits)
    except Exception as error:  # a sweep reports every failure and goes on
        return "error", f"{kind} {seed} MSTMM ERROR {type(error).__name__}: {error}"
    mstmm_seconds = time.perf_counter() - started
    started = time.perf_counter()
    try:
        reference = fe_frequencies(model, count=modes)
    except Exception as error:
        return "error", f"{kind} {seed} FE ERROR {type(error).__name__}: {error}"
    fe_seconds = time.perf_counter() - started
    ours, theirs = result.frequencies_hz, reference.frequencies_hz
    n = min(len(ours), len(theirs))
    difference = np.abs(ours[:n] / theirs[:n] - 1)
    trusted = reference.error_estimate[:n] < TRUSTED
    verdict, text = "ok", ""
    if len(ours) != len(theirs):
        verdict, text = "disagree", f"LEN {len(ours)} vs {len(theirs)}"
    elif (difference[trusted] > AGREEMENT).any():
        verdict, text = "disagree", (f"DISAGREE {difference[trusted].max():.1e} at "
                                     f"{np.flatnonzero(trusted & (difference > AGREEMENT))[:5].tolist()}")
    elif (difference > AGREEMENT).any():
        worst = np.argmax(difference)
        verdict, text = "untrusted", (f"fe-untrusted {difference[worst]:.1e} "
                                      f"(FE estimate {reference.error_estimate[worst]:.1e})")
    note = f" NOTE {result.note}" if result.note else ""
    return verdict, (f"{kind} {seed} {mstmm_seconds:.2f}s fe {fe_seconds:.2f}s {result.precision} "
                     f"{text}{note}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--modes", type=int, default=40)
    parser.add_argument("--seeds", type=int, nargs=2, default=(0, 10), metavar=("FIRST", "STOP"))
    parser.add_argument("--kinds", nargs="+", choices=KINDS, default=list(KINDS))
    parser.add_argument("--digits", type=int, default=None, help="natural_frequencies(digits=...)")
    args = parser.parse_args()
    tally: dict[str, int] = {}
    for seed in range(*args.seeds):
        for kind in args.kinds:
            verdict, line = compare(kind, seed, args.modes, args.digits)
            tally[verdict] = tally.get(verdict, 0) + 1
            print(line, flush=True)
    print(f"{args.modes} modes, seeds {args.seeds[0]}-{args.seeds[1] - 1}: "
          + ", ".join(f"{count} {verdict}" for verdict, count in sorted(tally.items())))


if __name__ == "__main__":
    main()
