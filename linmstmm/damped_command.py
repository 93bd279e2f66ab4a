"""``linmstmm freqs --damped``: damped natural frequencies and damping ratios.

``freqs MODEL --damped [--count N] [--fmax HZ] [--root POINT] [--json]``
starts from the lowest undamped natural frequencies (as ``freqs`` finds them)
and finds one complex root of det Ū_all per frequency with the spring
dashpots ``c`` and the model's Rayleigh ``[damping]`` acting
(:func:`linmstmm.damped.damped_frequencies`).
"""
from __future__ import annotations

import json

from linmstmm.model import ModelError, load_model


def add_damped_option(freqs) -> None:
    """Add ``--damped`` to the ``freqs`` parser; the command runs :func:`run_damped` with it.

    freqs : the ``freqs`` sub-parser, its ``run`` default already set.
    """
    freqs.add_argument("--damped", action="store_true",
                       help="damped natural frequencies and damping ratios, spring dashpots and [damping] "
                            "acting (complex roots of det Ubar_all)")
    undamped = freqs.get_default("run")
    freqs.set_defaults(run=lambda args: run_damped(args) if args.damped else undamped(args))


def run_damped(args) -> int:
    """Run ``linmstmm freqs --damped``; returns the exit status 0."""
    from linmstmm.cli import _request
    from linmstmm.damped import damped_frequencies

    model = load_model(args.model)
    if args.digits is not None:
        raise ModelError(model.source or model.name, "the damped roots are computed in float64 only; "
                         "leave out --digits with --damped", key="--digits")
    count, fmax = _request(args)
    result = damped_frequencies(model, count=count, fmax=fmax, root=args.root)
    if args.json:
        print(json.dumps(result.to_dict()))
        return 0
    print(f"{model.name}: damped natural frequencies (MSTMM, complex roots of det Ubar_all)")
    print(f"  rigid-body modes: {result.rigid_body_modes}")
    print(f"  {'mode':>4}  {'damped f [Hz]':>16}  {'damping ratio':>14}  {'|s|/2pi [Hz]':>16}")
    for index, (fd, zeta, fn) in enumerate(zip(result.damped_freq_hz, result.damping_ratio,
                                               result.natural_freq_hz), start=1):
        print(f"  {index:>4}  {fd:>16.10g}  {zeta:>14.6g}  {fn:>16.10g}")
    print(f"  solve time: {result.seconds * 1e3:.2f} ms")
    return 0
