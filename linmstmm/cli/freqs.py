"""``linmstmm freqs MODEL``: natural frequencies by the transfer matrix method.

With ``--damped``, the damped natural frequencies and damping ratios
(:mod:`linmstmm.cli.damped`).
"""
from __future__ import annotations

import argparse
import math

from linmstmm import load_model, natural_frequencies
from linmstmm.cli.damped import add_damped_option, run_damped
from linmstmm.cli.common import (
    add_output_options,
    add_request_options,
    as_options,
    emit,
    positive_float,
    positive_int,
    request,
    stages,
)
from linmstmm.determinant import BEAM_WEIGHT, KERNELS_PAY_FROM, PREDICTED_FIXED, PREDICTED_PAY_FROM
from linmstmm.roots import MAX_RTOL, MIN_RTOL


def add_freqs_command(subparsers) -> None:
    """Register ``freqs`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    freqs = subparsers.add_parser("freqs", help="natural frequencies by the transfer matrix method")
    add_request_options(freqs)
    add_output_options(freqs, csv_layout="one row per frequency")
    accuracy = freqs.add_mutually_exclusive_group()
    accuracy.add_argument("--digits", type=positive_int, default=None,
                          help="significant digits wanted (above 14 the mpmath path is used)")
    accuracy.add_argument("--rtol", type=certified_rtol, default=None, metavar="R",
                          help=f"relative accuracy each frequency is certified to, {MIN_RTOL:g} to {MAX_RTOL:g} "
                               "(default: polished to rounding, certified to 1e-9)")
    freqs.add_argument("--root", default=None, help="boundary point to use as the root")
    freqs.add_argument("--engine", choices=("auto", "numpy", "compiled"), default="auto",
                       help="how det Ū_all is evaluated: the numpy carry, or numba-compiled kernels "
                            "(about 5x cheaper per evaluation in a batch, 0.5-1.5 s to start in a new "
                            "process); auto: numpy in a new process, the kernels where the elements (a "
                            f"beam counting {BEAM_WEIGHT}) times the frequencies asked for reach "
                            f"{KERNELS_PAY_FROM:,} (for a large model polished from its predictions: "
                            f"times the frequencies + {PREDICTED_FIXED}, {PREDICTED_PAY_FROM:,}), once "
                            "they are compiled here")
    add_damped_option(freqs)
    freqs.set_defaults(run=run_freqs)


def certified_rtol(text: str) -> float:
    """``--rtol`` text as a relative accuracy in [MIN_RTOL, MAX_RTOL] (argparse type)."""
    value = positive_float(text)
    if value > MAX_RTOL:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_RTOL:g} (roots closer than that "
                                         f"are reported as one multiple root), got {text}")
    if value < MIN_RTOL:
        raise argparse.ArgumentTypeError(f"must be at least {MIN_RTOL:g} (float64's rounding; "
                                         f"--digits asks for more), got {text}")
    return value


def run_freqs(args) -> int:
    """Run ``linmstmm freqs``; returns the exit status 0."""
    if args.damped:
        return run_damped(args)
    model = load_model(args.model)
    count, fmax = request(args)
    with as_options(model, "root"), stages(args, "freqs"):
        result = natural_frequencies(model, count=count, fmax=fmax, digits=args.digits, root=args.root,
                                     engine=args.engine, rtol=args.rtol)
    data = result.to_dict()
    emit(args, model, data, lambda d: print_frequency_table(f"{model.name}: natural frequencies (MSTMM)", d,
                                                            args.rtol),
         lambda: frequency_csv(data))
    return 0


def frequency_texts(data: dict) -> tuple[list[str], list[str]]:
    """(f in Hz, ω in rad/s) as text: the mpmath digits where the result has them."""
    hz = data.get("frequencies_hz_text") or [f"{f:.12g}" for f in data["frequencies_hz"]]
    rad_s = data.get("omega_rad_s_text") or [f"{2 * math.pi * f:.12g}" for f in data["frequencies_hz"]]
    return hz, rad_s


def frequency_csv(data: dict) -> tuple[list[str], list[list]]:
    """The ``--csv`` table of a frequency result: mode, f [Hz], omega [rad/s], full precision."""
    hz = data.get("frequencies_hz_text") or [repr(f) for f in data["frequencies_hz"]]
    rad_s = data.get("omega_rad_s_text") or [repr(2 * math.pi * f) for f in data["frequencies_hz"]]
    return ["mode", "frequency [Hz]", "omega [rad/s]"], [[n, *pair] for n, pair in
                                                         enumerate(zip(hz, rad_s), start=1)]


def print_frequency_table(title: str, data: dict, rtol: float | None = None) -> None:
    """Print a frequency result (``to_dict`` of FrequencyResult or FEResult) as a table;
    with the ``rtol`` it was asked for, where one was (the digits beyond it are not certified)."""
    print(f"{title}")
    print(f"  rigid-body modes: {data['rigid_body_modes']}")
    if "ubar_order" in data:
        print(f"  order of Ubar_all: {data['ubar_order']}")
    if data.get("precision", "float64") != "float64":
        print(f"  precision: {data['precision']}")
    if rtol is not None:
        print(f"  certified to: rtol {rtol:.0e} (each frequency within it of the root; digits beyond it are not)")
    hz, rad_s = frequency_texts(data)
    width = max([20] + [len(text) for text in hz + rad_s])
    print(f"  {'mode':>4}  {'f [Hz]':>{width}}  {'omega [rad/s]':>{width}}")
    for index, (f, omega) in enumerate(zip(hz, rad_s), start=1):
        print(f"  {index:>4}  {f:>{width}}  {omega:>{width}}")
    engine = f" ({data['engine']} engine)" if "engine" in data else ""
    print(f"  solve time: {data['seconds'] * 1e3:.2f} ms{engine}")
    if data.get("note"):
        print(f"  note: {data['note']}")
