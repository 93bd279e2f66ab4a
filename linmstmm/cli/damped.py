"""``linmstmm freqs MODEL --damped``: damped natural frequencies and damping ratios.

``freqs MODEL --damped [--count N] [--fmax HZ] [--root POINT]`` starts from the
lowest undamped natural frequencies (as ``freqs`` finds them) and finds one
complex root of det Ū_all per frequency with the spring dashpots ``c`` and the
model's Rayleigh ``[damping]`` acting (:func:`linmstmm.damped_frequencies`).
The option is registered on ``freqs`` (:func:`add_damped_option`); the output
options (``--json``, ``--output``, ``--csv``) are those of ``freqs``, the JSON
keys in ``docs/cli.md``.
"""
from __future__ import annotations

from linmstmm import ModelError, load_model
from linmstmm.cli.common import as_options, emit, request, source, stages


def add_damped_option(freqs) -> None:
    """Add ``--damped`` to the ``freqs`` parser; :func:`run_damped` runs with it.

    Parameters
    ----------
    freqs : argparse.ArgumentParser
        The ``freqs`` sub-parser; its ``run`` checks ``args.damped``.
    """
    freqs.add_argument("--damped", action="store_true",
                       help="damped natural frequencies and damping ratios, spring dashpots and [damping] "
                            "acting (complex roots of det Ubar_all); not with --digits")


def run_damped(args) -> int:
    """Run ``linmstmm freqs --damped``; returns the exit status 0."""
    from linmstmm import damped_frequencies  # here: freqs without --damped starts without it

    model = load_model(args.model)
    if args.digits is not None:
        raise ModelError(source(model), "the damped roots are computed in float64 only; "
                         "leave out --digits with --damped", key="--digits")
    count, fmax = request(args)
    with as_options(model, "root", "fmax"), stages(args, "freqs --damped"):
        result = damped_frequencies(model, count=count, fmax=fmax, root=args.root)
    data = result.to_dict()
    emit(args, model, data, print_damped_table, lambda: damped_csv(data))
    return 0


def damped_csv(data: dict) -> tuple[list[str], list[list]]:
    """The ``--csv`` table of ``freqs --damped``: mode, damped frequency, damping ratio, |s|/2π,
    and s, full precision."""
    header = ["mode", "damped frequency [Hz]", "damping ratio", "frequency |s|/2pi [Hz]",
              "s real [1/s]", "s imag [1/s]"]
    rows = [[n, fd, zeta, fn, *s] for n, (fd, zeta, fn, s) in
            enumerate(zip(data["damped_frequencies_hz"], data["damping_ratio"], data["frequencies_hz"],
                          data["roots"]), start=1)]
    return header, rows


def print_damped_table(data: dict) -> None:
    """Print the ``to_dict`` of a DampedResult as a table."""
    print(f"{data['model']}: damped natural frequencies (MSTMM, complex roots of det Ubar_all)")
    print(f"  rigid-body modes: {data['rigid_body_modes']}")
    print(f"  {'mode':>4}  {'damped f [Hz]':>16}  {'damping ratio':>14}  {'|s|/2pi [Hz]':>16}")
    for index, (fd, zeta, fn) in enumerate(zip(data["damped_frequencies_hz"], data["damping_ratio"],
                                               data["frequencies_hz"]), start=1):
        print(f"  {index:>4}  {fd:>16.10g}  {zeta:>14.6g}  {fn:>16.10g}")
    print(f"  solve time: {data['seconds'] * 1e3:.2f} ms")
