"""Command ``linmstmm fe MODEL``: natural frequencies by the finite-element route.

``fe MODEL [--count N] [--fmax HZ] [--json] [--elements-per-beam N] [--rtol R]``
takes the same request as ``freqs`` and answers from :func:`linmstmm.fe.fe_frequencies`
(global M and K, natural-factor eigensolver, mesh doubling with Richardson
extrapolation unless ``--elements-per-beam`` fixes the mesh). ``--json``
prints :meth:`linmstmm.fe.FEResult.to_dict`: the ``freqs`` keys ``model``,
``frequencies_hz``, ``rigid_body_modes``, ``seconds`` plus ``error_estimate``
(relative, per frequency), ``elements_per_beam``, ``n_dof`` and
``"method": "fe"`` and, when set, ``note``. The table prints the note once,
after the frequencies.

Errors follow the CLI contract: a bad model or option exits 2 (raised as
ModelError / UsageError); a failed computation exits 1 (ComputationError).
"""
from __future__ import annotations

import json

import numpy as np


def add_fe_command(subparsers):
    """Register ``fe`` on ``subparsers`` (from ``ArgumentParser.add_subparsers``).

    Returns the new subparser.
    """
    # Imported here: linmstmm.cli imports this module to wire the command in.
    from linmstmm.cli import _add_request_options, _positive_float, _positive_int

    fe = subparsers.add_parser("fe", help="natural frequencies by the finite-element route (cross-check)")
    _add_request_options(fe)
    fe.add_argument("--elements-per-beam", type=_positive_int, default=None, metavar="N",
                    help="fixed mesh of N elements per beam (default: refine until --rtol)")
    fe.add_argument("--rtol", type=_positive_float, default=1e-9, metavar="R",
                    help="target relative error when refining the mesh (default 1e-9)")
    fe.set_defaults(run=run_fe)
    return fe


def run_fe(args) -> int:
    """Run ``linmstmm fe``: print a table, or one JSON object with ``--json``."""
    from scipy.sparse.linalg import ArpackError

    from linmstmm.cli import ComputationError, _print_frequency_table, _request
    from linmstmm.fe import fe_frequencies
    from linmstmm.model import load_model

    model = load_model(args.model)
    count, fmax = _request(args)
    try:
        result = fe_frequencies(model, count=count, fmax=fmax,
                                elements_per_beam=args.elements_per_beam, rtol=args.rtol)
    except (np.linalg.LinAlgError, ArpackError) as error:
        raise ComputationError(f"{args.model}: finite-element solve failed: {error}") from error
    data = result.to_dict()
    if args.json:
        print(json.dumps(data))
        return 0
    _print_frequency_table(f"{model.name}: natural frequencies (finite elements)", data)
    mesh = "no beams" if result.elements_per_beam is None else \
        f"{result.elements_per_beam} elements per beam"
    print(f"  mesh: {mesh}, {result.n_dof} DOFs")
    if np.isfinite(result.error_estimate).any():
        print(f"  largest estimated relative error: {np.nanmax(result.error_estimate):.1e}")
    return 0
