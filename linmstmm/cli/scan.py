"""``linmstmm scan MODEL --fmax HZ --plot FILE``: log|det Ū_all| and the root count over frequency."""
from __future__ import annotations

from linmstmm import load_model
from linmstmm.cli.common import (
    add_model_argument,
    add_output_options,
    emit,
    positive_float,
    positive_int,
    stages,
    writing,
)
from linmstmm.studies import DEFAULT_SCAN_POINTS, determinant_scan


def add_scan_command(subparsers) -> None:
    """Register ``scan`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    scan = subparsers.add_parser("scan", help="plot log|det Ubar_all| and the root count over frequency")
    add_model_argument(scan)
    scan.add_argument("--fmax", type=positive_float, required=True, help="top of the scan, Hz")
    scan.add_argument("--points", type=positive_int, default=DEFAULT_SCAN_POINTS,
                      help=f"frequencies in the scan (default {DEFAULT_SCAN_POINTS})")
    scan.add_argument("--plot", metavar="FILE", required=True, help="the scan figure (PNG)")
    add_output_options(scan)
    scan.set_defaults(run=run_scan)


def run_scan(args) -> int:
    """Run ``linmstmm scan``; returns the exit status 0."""
    from linmstmm.plot import plot_scan

    model = load_model(args.model)
    with stages(args, "scan"):
        scan = determinant_scan(model, args.fmax, args.points)
    with writing(model, "--plot", args.plot):
        plot_scan(scan.omega, scan.sign, scan.log_abs, scan.roots, scan.count(), args.plot,
                  title=f"{model.name}: det Ū_all, {scan.roots.size} natural frequencies up to {args.fmax:g} Hz")
    data = {**scan.to_dict(), "plot": str(args.plot)}

    def table(data):
        print(f"{model.name}: det Ubar_all (order {data['ubar_order']}) scanned at {args.points} "
              f"frequencies up to {args.fmax:g} Hz")
        print(f"  natural frequencies [Hz]: {', '.join(f'{f:.8g}' for f in data['frequencies_hz']) or 'none'}")
        if data.get("note"):
            print(f"  note: {data['note']}")
        print(f"  wrote {args.plot}")

    emit(args, model, data, table)
    return 0
