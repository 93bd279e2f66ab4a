"""``linmstmm sweep MODEL --vary KEY=START:STOP:N[:log] ...``: a parameter study.

The study is :func:`linmstmm.sweep.sweep`; the JSON is
:meth:`linmstmm.sweep.SweepResult.to_dict` (keys in ``docs/cli.md``). A
malformed ``--vary``, an unknown key or a step that breaks the model contract
exits with status 2 (one line naming the file and the key).
"""
from __future__ import annotations

import numpy as np

from linmstmm import load_model
from linmstmm.cli.common import (
    UsageError,
    add_model_argument,
    add_output_options,
    emit,
    parsed_by,
    positive_int,
    writing,
)
from linmstmm.determinant import ENGINES
from linmstmm.parameters import parse_key, unit
from linmstmm.sweep import ENGINE, Vary, grid, sweep
from linmstmm.tracking import SAME_MODE_MAC

#: Elastic frequencies per step unless --count says otherwise.
DEFAULT_COUNT = 5


def add_sweep_command(subparsers) -> None:
    """Register ``sweep`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    command = subparsers.add_parser("sweep", help="natural frequencies over a grid of model values, "
                                                  "modes tracked by shape")
    add_model_argument(command)
    command.add_argument("--vary", type=parsed_by(Vary.parse), action="append", required=True,
                         metavar="KEY=START:STOP:N[:log]",
                         help="a value of the model (e.g. spring.k1.k[2], beam.arm.E, rigid.m2.mass, "
                              "points.tip[0]) from START to STOP in N steps (:log geometric); several form a grid")
    command.add_argument("--zip", action="store_true", help="pair the --vary ranges (same N) instead of a grid")
    command.add_argument("--count", type=positive_int, default=DEFAULT_COUNT, metavar="K",
                         help=f"elastic frequencies per step (default {DEFAULT_COUNT})")
    command.add_argument("--plot", metavar="FILE", help="PNG: tracked frequencies against the first key")
    command.add_argument("--sensitivity", action="store_true",
                         help="df/dp of every varied key at every step, from the mode shapes")
    command.add_argument("--workers", type=positive_int, default=1, metavar="N",
                         help="local processes running the steps (default 1)")
    command.add_argument("--dask", metavar="ADDRESS",
                         help="run the steps on a dask.distributed scheduler; 'local' starts a LocalCluster")
    command.add_argument("--engine", choices=ENGINES, default=ENGINE,
                         help=f"how every step evaluates det Ubar_all (default {ENGINE}: numpy, as "
                              "'linmstmm freqs' in a new process, unless the steps each process runs, times "
                              "--count, times the model's elements make work enough to pay for loading the "
                              "numba kernels; compiled: the kernels in every process, faster on long sweeps "
                              "and large models)")
    command.add_argument("--warm-start", action="store_true",
                         help="start each step's root search from its neighbouring step's frequencies")
    add_output_options(command, csv_layout="one row per step (values, tracked frequencies, ranks, sensitivities)")
    command.set_defaults(run=run_sweep)


def run_sweep(args) -> int:
    """Run ``linmstmm sweep``; returns the exit status 0."""
    model = load_model(args.model)
    try:
        steps, shape = grid(args.vary, zipped=args.zip)
    except ValueError as error:
        raise UsageError(f"linmstmm sweep: --vary: {error}") from None
    try:
        result = sweep(model, steps, count=args.count, shape=shape, sensitivity=args.sensitivity,
                       workers=args.workers, dask=args.dask, progress=not args.quiet,
                       engine=args.engine, warm_start=args.warm_start)
    except OSError as error:  # a scheduler that cannot be reached
        raise UsageError(f"linmstmm sweep: --dask {args.dask}: {error}") from None
    data = result.to_dict()
    if args.plot:
        with writing(model, "--plot", args.plot):
            plot_sweep(result, args.plot, log_x=args.vary[0].log)
        data["plot"] = str(args.plot)

    def table(_):
        print_table(result)
        if args.plot:
            print(f"  wrote {args.plot}")

    emit(args, model, data, table, lambda: csv_table(model, result))
    return 0


def print_table(result) -> None:
    """Print the sweep as a text table: values, then the tracked frequencies, per step."""
    count = result.order.shape[1]
    print(f"{result.model}: natural frequencies over {len(result.values)} steps "
          f"({result.workers}, {result.engine} engine{', warm starts' if result.warm_start else ''}, "
          f"{result.seconds:.2f} s); columns follow mode shapes (MAC)")
    head = [f"{key:>14}" for key in result.keys] + [f"{'mode ' + str(c + 1) + ' [Hz]':>14}" for c in range(count)]
    print("  " + "  ".join(head))
    for values, row, switched in zip(result.values, result.frequencies_hz, result.switched):
        cells = [f"{v:>14.6g}" for v in values] + [f"{f:>13.8g}{'*' if s else ' '}" for f, s in zip(row, switched)]
        print("  " + "  ".join(cells))
    if result.switched.any():
        print(f"  * another mode than the step before (MAC below {SAME_MODE_MAC:g}): the mode this column "
              f"followed left the lowest {count}")
    for step, note in result.notes.items():
        print(f"  note (step {step + 1}): {note}")


def csv_table(model, result) -> tuple[list[str], list[list[str]]]:
    """The ``--csv`` table: (header, rows), one row per step.

    Columns: every varied key ``KEY [unit]``, the tracked frequencies
    ``mode c [Hz]``, the rank of each column's mode ``mode c rank`` (1 = lowest),
    its MAC against the step before ``mode c MAC`` (below SAME_MODE_MAC: another
    mode) and, with sensitivities, ``dmode c/dKEY [Hz/unit]``; empty cells where a
    step has fewer modes.
    """
    count = result.order.shape[1]
    units = {key: unit(parse_key(model, key)) for key in result.keys}
    header = [f"{key} [{units[key]}]" for key in result.keys] + [f"mode {c + 1} [Hz]" for c in range(count)] + \
        [f"mode {c + 1} rank" for c in range(count)] + [f"mode {c + 1} MAC" for c in range(count)]
    blocks = [result.values, result.frequencies_hz, result.order + 1.0, result.tracking_mac]
    for key, values in result.sensitivities.items():
        header += [f"dmode {c + 1}/d{key} [{_per(units[key])}]" for c in range(count)]
        blocks.append(values)
    return header, [[_cell(v) for v in row] for row in np.hstack(blocks)]


def _per(key_unit: str) -> str:
    """The unit of Hz per ``key_unit``."""
    if key_unit == "1":
        return "Hz"
    return f"Hz/{key_unit}" if " " not in key_unit and "/" not in key_unit else f"Hz/({key_unit})"


def _cell(value: float) -> str:
    """A CSV cell: "" for nan, whole numbers without a decimal point, else the shortest repr."""
    if np.isnan(value):
        return ""
    return str(int(value)) if float(value).is_integer() and abs(value) < 2**53 else repr(float(value))


def plot_sweep(result, path, log_x: bool = False) -> None:
    """Write a PNG of the tracked frequencies (Hz) against the first varied key
    (:meth:`linmstmm.sweep.SweepResult.plot`). log_x : logarithmic value axis."""
    result.plot(log_x=log_x).savefig(path, format="png", dpi=130)
