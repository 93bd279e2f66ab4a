"""Command ``linmstmm sweep MODEL --vary KEY=START:STOP:N[:log] ...``: a parameter study.

Options: ``--zip`` (pair the ranges instead of their grid), ``--count K``,
``--json``, ``--csv FILE``, ``--plot FILE``, ``--sensitivity``, ``--workers N``,
``--dask ADDRESS|local``, ``--quiet``. The study is :func:`linmstmm.sweep.sweep`;
the JSON is :meth:`linmstmm.sweep.SweepResult.to_dict` (keys in ``docs/cli.md``).

A malformed ``--vary``, an unknown key or a step that breaks the model
contract exits with status 2 (one line naming the file and the key).
"""
from __future__ import annotations

import argparse
import csv
import json

import numpy as np

#: Elastic frequencies per step unless --count says otherwise.
DEFAULT_COUNT = 5


def add_sweep_command(subparsers):
    """Register ``sweep`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``).

    Returns the new subparser.
    """
    # Imported here: linmstmm.cli imports this module to wire the command in.
    from linmstmm.cli import _positive_int

    sweep = subparsers.add_parser("sweep", help="natural frequencies over a grid of model values, "
                                                "modes tracked by shape")
    sweep.add_argument("model", help="model file (TOML, see model-format.md)")
    sweep.add_argument("--vary", type=_vary, action="append", required=True, metavar="KEY=START:STOP:N[:log]",
                       help="a value of the model (e.g. spring.k1.k[2], beam.arm.E, rigid.m2.mass, "
                            "points.tip[0]) from START to STOP in N steps (:log geometric); several form a grid")
    sweep.add_argument("--zip", action="store_true", help="pair the --vary ranges (same N) instead of a grid")
    sweep.add_argument("--count", type=_positive_int, default=DEFAULT_COUNT, metavar="K",
                       help=f"elastic frequencies per step (default {DEFAULT_COUNT})")
    sweep.add_argument("--json", action="store_true", help="one JSON object on stdout")
    sweep.add_argument("--csv", metavar="FILE", help="one row per step: values, tracked frequencies")
    sweep.add_argument("--plot", metavar="FILE", help="PNG: tracked frequencies against the first key")
    sweep.add_argument("--sensitivity", action="store_true",
                       help="df/dp of every varied key at every step, from the mode shapes")
    sweep.add_argument("--workers", type=_positive_int, default=1, metavar="N",
                       help="local processes running the steps (default 1)")
    sweep.add_argument("--dask", metavar="ADDRESS",
                       help="run the steps on a dask.distributed scheduler; 'local' starts a LocalCluster")
    sweep.add_argument("--quiet", action="store_true", help="no progress bar on stderr")
    sweep.set_defaults(run=run_sweep)
    return sweep


def _vary(text):
    """argparse type of --vary: a :class:`linmstmm.sweep.Vary`."""
    from linmstmm.sweep import Vary

    try:
        return Vary.parse(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def run_sweep(args) -> int:
    """Run ``linmstmm sweep``: a table (or JSON), and the CSV and figure asked for."""
    from linmstmm.cli import UsageError
    from linmstmm.mode_commands import _writing
    from linmstmm.model import load_model
    from linmstmm.sweep import grid, sweep

    model = load_model(args.model)
    try:
        steps, shape = grid(args.vary, zipped=args.zip)
    except ValueError as error:
        raise UsageError(f"linmstmm sweep: --vary: {error}") from None
    try:
        result = sweep(model, steps, count=args.count, shape=shape, sensitivity=args.sensitivity,
                       workers=args.workers, dask=args.dask, progress=not args.quiet)
    except OSError as error:  # a scheduler that cannot be reached
        raise UsageError(f"linmstmm sweep: --dask {args.dask}: {error}") from None
    if args.csv:
        with _writing(model, "--csv", args.csv):
            write_csv(result, args.csv)
    if args.plot:
        with _writing(model, "--plot", args.plot):
            plot_sweep(result, args.plot, log_x=args.vary[0].log)
    if args.json:
        print(json.dumps(result.to_dict()))
    else:
        _print_table(result)
    return 0


def _print_table(result) -> None:
    """The sweep as a text table: values, then the tracked frequencies, per step."""
    count = result.order.shape[1]
    print(f"{result.model}: natural frequencies over {len(result.values)} steps "
          f"({result.workers}, {result.seconds:.2f} s); columns follow mode shapes (MAC)")
    head = [f"{key:>14}" for key in result.keys] + [f"{'mode ' + str(c + 1) + ' [Hz]':>14}" for c in range(count)]
    print("  " + "  ".join(head))
    for values, row in zip(result.values, result.frequencies_hz):
        cells = [f"{v:>14.6g}" for v in values] + [f"{f:>14.8g}" for f in row]
        print("  " + "  ".join(cells))
    for step, note in result.notes.items():
        print(f"  note (step {step + 1}): {note}")


def csv_columns(result) -> tuple[list[str], np.ndarray]:
    """(header, (steps, columns) table) of the CSV file: the varied values, the tracked
    frequencies ``mode_c_hz``, the rank of each column's mode ``mode_c_rank`` (1 = lowest)
    and, with sensitivities, ``dmode_c_hz/dKEY``."""
    count = result.order.shape[1]
    header = list(result.keys) + [f"mode_{c + 1}_hz" for c in range(count)] + \
        [f"mode_{c + 1}_rank" for c in range(count)]
    blocks = [result.values, result.frequencies_hz, result.order + 1.0]
    for key, values in result.sensitivities.items():
        header += [f"dmode_{c + 1}_hz/d{key}" for c in range(count)]
        blocks.append(values)
    return header, np.hstack(blocks)


def write_csv(result, path) -> None:
    """Write the CSV of :func:`csv_columns` (empty cells where a step has fewer modes)."""
    header, table = csv_columns(result)
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(header)
        writer.writerows([[_cell(v) for v in row] for row in table])


def _cell(value: float) -> str:
    """A CSV cell: "" for nan, whole numbers without a decimal point, else the shortest repr."""
    if np.isnan(value):
        return ""
    return str(int(value)) if float(value).is_integer() and abs(value) < 2**53 else repr(float(value))


def plot_sweep(result, path, log_x: bool = False) -> None:
    """Write a PNG of the tracked frequencies (Hz) against the first varied key.

    One colour per tracked column; with a grid of several keys, one line per
    combination of the other keys' values. log_x : logarithmic value axis.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(7.5, 4.8), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots()
    lines = result.values.shape[0] // result.shape[0]
    x = result.values[:, 0].reshape(result.shape[0], lines)
    frequencies = result.frequencies_hz.reshape(result.shape[0], lines, -1)
    for column in range(frequencies.shape[2]):
        colour = f"C{column % 10}"
        for line in range(lines):
            axes.plot(x[:, line], frequencies[:, line, column], "-o", color=colour, markersize=2.5,
                      lw=1.2, label=f"mode {column + 1}" if line == 0 else None)
    if log_x:
        axes.set_xscale("log")
    axes.set_xlabel(result.keys[0])
    axes.set_ylabel("natural frequency [Hz]")
    others = f"; one line per value of {', '.join(result.keys[1:])}" if len(result.shape) > 1 else ""
    axes.set_title(f"{result.model}: modes followed by shape (MAC){others}", fontsize=9)
    axes.legend(fontsize=8)
    axes.grid(alpha=0.3)
    figure.savefig(path, format="png", dpi=130)
