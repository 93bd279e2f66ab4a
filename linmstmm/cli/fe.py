"""``linmstmm fe MODEL``: natural frequencies by the finite-element route (the independent check).

Takes the same request as ``freqs`` and answers from :func:`linmstmm.fe_frequencies`
(global M and K, natural-factor eigensolver, mesh doubling with Richardson
extrapolation unless ``--elements-per-beam`` fixes the mesh).
"""
from __future__ import annotations

import numpy as np

from linmstmm import fe_frequencies, load_model
from linmstmm.cli.common import (
    ComputationError,
    add_output_options,
    add_request_options,
    emit,
    positive_float,
    positive_int,
    request,
)
from linmstmm.cli.freqs import frequency_csv, print_frequency_table


def add_fe_command(subparsers) -> None:
    """Register ``fe`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``)."""
    fe = subparsers.add_parser("fe", help="natural frequencies by the finite-element route (cross-check)")
    add_request_options(fe)
    add_output_options(fe, csv_layout="one row per frequency")
    fe.add_argument("--elements-per-beam", type=positive_int, default=None, metavar="N",
                    help="fixed mesh of N elements per beam (default: refine until --rtol)")
    fe.add_argument("--rtol", type=positive_float, default=1e-9, metavar="R",
                    help="target relative error when refining the mesh (default 1e-9)")
    fe.set_defaults(run=run_fe)


def run_fe(args) -> int:
    """Run ``linmstmm fe``: print a table, or one JSON object with ``--json``."""
    from scipy.sparse.linalg import ArpackError

    model = load_model(args.model)
    count, fmax = request(args)
    try:
        result = fe_frequencies(model, count=count, fmax=fmax,
                                elements_per_beam=args.elements_per_beam, rtol=args.rtol)
    except (np.linalg.LinAlgError, ArpackError) as error:
        raise ComputationError(f"{args.model}: finite-element solve failed: {error}") from error
    data = result.to_dict()

    def table(data):
        print_frequency_table(f"{model.name}: natural frequencies (finite elements)", data)
        mesh = "no beams" if result.elements_per_beam is None else \
            f"{result.elements_per_beam} element{'' if result.elements_per_beam == 1 else 's'} per beam"
        print(f"  mesh: {mesh}, {result.n_dof} DOFs")
        if np.isfinite(result.error_estimate).any():
            print(f"  largest estimated relative error: {np.nanmax(result.error_estimate):.1e}")

    emit(args, model, data, table, lambda: frequency_csv(data))
    return 0
