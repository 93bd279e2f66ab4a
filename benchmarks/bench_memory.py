"""Peak memory of a solve: the transfer-matrix route against the FE route, side by side.

    python benchmarks/bench_memory.py [--report reports/memory.md]

Each solve runs in a process of its own. The process first imports the
package, loads every compiled kernel the solve will call (solves of three
small models: a spring chain, a beam clamped at both ends, which is held at
free points and statically indeterminate, and a free beam, whose rigid-body
modes are counted at complex frequencies; by both routes for the FE route,
whose node constraints the kernels make once loaded) and loads the model; then
Linux's record of its peak resident set is reset (``/proc/self/clear_refs``),
its resident set read, the solve made, and the peak read (``VmHWM``). The
difference is the memory the solve adds at its peak: what a user's machine
must have free beyond the session that holds the model. A kernel loaded from
numba's cache adds 0.5 to 2 MiB of its own, so a solve that loads one is
refused (the warm-up is to be widened). The ratio column is FE over MSTMM in
the same run. Linux only; not part of the test suite.

Routes: *MSTMM*, :func:`linmstmm.natural_frequencies` as a user calls it once
the kernels are loaded (``engine="auto"``: the compiled kernels, or the numpy
carry for a model made mostly of a repeated cell, which it takes by powers of
the cell's matrix), compilation of the model included; *FE*,
:func:`linmstmm.fe.fe_frequencies` with its automatic refinement (what the
``fe`` command runs). Times are in ``reports/speed.md`` and
``reports/speed_accuracy.md``, not here.
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: (label, how the model is made (Python expression, ``common`` imported), frequencies asked for).
CASES = (
    ("launcher, 10 lowest", "load_model('models/mlrs/mlrs.toml')", 10),
    ("launcher, 100 lowest", "load_model('models/mlrs/mlrs.toml')", 100),
    ("launcher 2, 100 lowest", "load_model('models/launcher2/launcher2.toml')", 100),
    ("spring–mass chain of 10,000 bodies, 20 lowest", "common.spring_chain(10000)", 20),
    ("cantilever of 1,000 beam elements, 20 lowest", "common.beam_chain(1000)", 20),
)

#: The child process: loads the kernels, reads its peak, solves, reads its peak again.
_CHILD = """
import json, sys

import numpy as np

def kib(field):
    for line in open('/proc/self/status'):
        if line.startswith(field + ':'):
            return int(line.split()[1])

def kernel_signatures():
    return {{(module.__name__, name, str(signature)) for module in list(sys.modules.values())
            if getattr(module, '__name__', '').startswith('linmstmm._') and module.__name__.endswith('kernels')
            for name, kernel in vars(module).items() if hasattr(kernel, 'signatures')
            for signature in kernel.signatures}}

sys.path.insert(0, 'benchmarks')
import common
from linmstmm import load_model, natural_frequencies
from linmstmm.fe import fe_frequencies
from linmstmm.model import Model
route, count = sys.argv[1], int(sys.argv[2])
beam = common.beam_chain(2)
clamped = Model('beam clamped at both ends', beam.points, beams=beam.beams,
                boundary={{'p0': np.ones(6, dtype=bool), 'p2': np.ones(6, dtype=bool)}})
for small in (common.spring_chain(3), clamped, Model('free beam', beam.points, beams=beam.beams)):
    natural_frequencies(small, 2, engine='compiled')
    if route == 'fe':
        fe_frequencies(small, 2)
model = {model}
loaded = kernel_signatures()
with open('/proc/self/clear_refs', 'w') as peak:
    peak.write('5')
before = kib('VmRSS')
if route == 'fe':
    fe_frequencies(model, count)
else:
    natural_frequencies(model, count)
after = kib('VmHWM')
missed = sorted(kernel_signatures() - loaded)
if missed:
    raise SystemExit(f'the solve loaded kernels the warm-up did not: {{missed}}')
print(json.dumps(dict(before=before, after=after)))
"""


def measured(model: str, route: str, count: int) -> dict:
    """{before, after}: a new process's resident set before one solve and its peak during it (KiB)."""
    run = subprocess.run([sys.executable, "-c", _CHILD.format(model=model), route, str(count)], cwd=REPO,
                         capture_output=True, text=True)
    if run.returncode:
        raise RuntimeError(f"{route}, {model}: {run.stderr.strip()}")
    return json.loads(run.stdout.strip().splitlines()[-1])


def _as_markdown(text: str) -> str:
    """The module docstring's paragraphs (reStructuredText) as markdown: roles and double
    backquotes as code, each paragraph on one line."""
    text = re.sub(r":func:`([^`]+)`", r"`\1`", text).replace("``", "`")
    return "\n\n".join(" ".join(paragraph.split()) for paragraph in text.split("\n\n"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--report", type=Path, help="write the table as markdown here")
    args = parser.parse_args()
    lines = ["| model | MSTMM: peak added | FE: peak added | FE / MSTMM |", "|---|---:|---:|---:|"]
    for label, model, count in CASES:
        mstmm, fe = measured(model, "mstmm", count), measured(model, "fe", count)
        added = [(r["after"] - r["before"]) / 1024 for r in (mstmm, fe)]
        ratio = f"{added[1] / added[0]:.1f}" if added[0] > 0 else "—"
        lines.append(f"| {label} | {added[0]:.1f} MiB | {added[1]:.1f} MiB | {ratio} |")
        print(lines[-1], flush=True)
    if args.report:
        when = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
        args.report.write_text("\n".join([
            "# Peak memory of a solve: MSTMM against the FE route", "",
            f"Generated by `python benchmarks/bench_memory.py --report {args.report}` on {when}.", "",
            _as_markdown(__doc__.split("\n\n", 2)[2].strip()), "",
            *lines, ""]))


if __name__ == "__main__":
    main()
