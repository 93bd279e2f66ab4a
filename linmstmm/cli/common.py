"""What the commands share: option types, the request options, output files, errors, progress.

Every command prints a table on stdout, or one JSON object with ``--json``;
``--output FILE`` writes that JSON object to FILE and ``--csv FILE`` a table
of numbers (layouts in ``docs/cli.md``). Progress bars go to stderr, only
when stderr is a terminal and ``--quiet`` is not given.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from contextlib import contextmanager

from linmstmm import ModelError
from linmstmm.stages import listening


class UsageError(Exception):
    """A bad option or an impossible request (exit status 2)."""


class ComputationError(Exception):
    """The computation could not deliver what was asked (exit status 1)."""


def positive_int(text: str) -> int:
    """An option's text as an integer >= 1 (argparse type)."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value


def positive_float(text: str) -> float:
    """An option's text as a positive finite number (argparse type)."""
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


def damping_ratios(text: str) -> list[float]:
    """``--zeta`` text "0.02" or "0.01,0.02,..." as a list of finite ratios >= 0 (argparse type)."""
    try:
        ratios = [float(part) for part in text.split(",")]
    except ValueError:
        ratios = [math.nan]
    if not all(math.isfinite(r) and r >= 0 for r in ratios):
        raise argparse.ArgumentTypeError(f"must be damping ratios >= 0, one or a comma list, got {text}")
    return ratios


def parsed_by(parse):
    """An argparse ``type`` calling ``parse(text)``, its ValueError the option's one-line error.

    Parameters
    ----------
    parse : callable
        str -> value, raising ValueError for a malformed text (e.g. ``Vary.parse``).

    Returns
    -------
    callable
        The ``type`` for ``add_argument``.
    """
    def convert(text):
        try:
            return parse(text)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    return convert


def add_model_argument(parser) -> None:
    """The positional MODEL of every command."""
    parser.add_argument("model", help="model file (TOML, see model-format.md)")


def add_request_options(parser) -> None:
    """MODEL, ``--count`` and ``--fmax``: which natural frequencies are wanted."""
    add_model_argument(parser)
    parser.add_argument("--count", type=positive_int, default=None,
                        help="the lowest N elastic frequencies (default 10 unless --fmax)")
    parser.add_argument("--fmax", type=positive_float, default=None,
                        help="all elastic frequencies up to HZ")


def add_output_options(parser, csv_layout: str | None = None) -> None:
    """``--json``, ``--output FILE``, ``--quiet`` and, given its layout, ``--csv FILE``."""
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    parser.add_argument("--output", metavar="FILE", default=None,
                        help="write the JSON object to FILE (the table still goes to stdout)")
    if csv_layout:
        parser.add_argument("--csv", metavar="FILE", default=None,
                            help=f"write {csv_layout} to FILE as CSV, units in the column headers")
    parser.add_argument("--quiet", action="store_true", help="no progress bars on stderr")


def add_zeta_option(parser) -> None:
    """``--zeta Z[,Z...]``: modal damping ratios."""
    parser.add_argument("--zeta", type=damping_ratios, default=None, metavar="Z[,Z...]",
                        help="modal damping ratios: one for all elastic modes or one per elastic mode "
                             "(replaces the model's [damping])")


def request(args) -> tuple[int | None, float | None]:
    """(count, fmax) as the solvers want them: ``--count`` defaults to 10 without ``--fmax``."""
    count = args.count
    if count is None and args.fmax is None:
        count = 10
    return count, args.fmax


def source(model) -> str:
    """The file name errors carry for ``model``."""
    return model.source or model.name


@contextmanager
def writing(model, option: str, path):
    """Turn an OSError while writing ``path`` into a ModelError on ``option``."""
    try:
        yield
    except OSError as error:
        raise ModelError(source(model), f"cannot write {str(path)!r}: {error.strerror or error}",
                         key=option) from error


#: Library parameters whose option is not named after them.
OPTION_OF = {"damping_ratio": "--zeta"}


def option_of(parameter: str) -> str:
    """The option that sets the library's ``parameter``: ``--response-points`` for
    ``response_points``, ``--zeta`` for ``damping_ratio`` (:data:`OPTION_OF`)."""
    return OPTION_OF.get(parameter, "--" + parameter.replace("_", "-"))


@contextmanager
def as_options(model, *parameters: str):
    """Name the option, not the library's parameter, in errors on ``parameters``.

    A ModelError whose key is one of ``parameters`` (``response_points``,
    ``damping_ratio``) is raised again with the key of the option
    (``--response-points``, ``--zeta``: :func:`option_of`); a
    DampingRatioError becomes a ModelError on ``--zeta``.
    """
    try:
        yield
    except ModelError as error:
        if error.key not in parameters:
            raise
        raise ModelError(error.file, error.message, error.element, key=option_of(error.key)) from error
    except ValueError as error:
        # here, not at the top: a command that raises it has loaded linmstmm.response, which
        # freqs, check and fe start without
        from linmstmm.response import DampingRatioError

        if not isinstance(error, DampingRatioError):
            raise
        raise ModelError(source(model), str(error), key="--zeta") from error


def emit(args, model, data: dict, table, csv_table=None) -> None:
    """Deliver a command's result: JSON (stdout and/or ``--output``), ``--csv``, or the table.

    data : the JSON object. table : function printing the table of ``data``.
    csv_table : function returning (header, rows) for ``--csv``.
    """
    written = []
    if args.output:
        with writing(model, "--output", args.output), open(args.output, "w", encoding="utf-8") as file:
            json.dump(data, file)
            file.write("\n")
        written.append(args.output)
    if getattr(args, "csv", None):
        header, rows = csv_table()
        with writing(model, "--csv", args.csv), open(args.csv, "w", newline="", encoding="utf-8") as file:
            out = csv.writer(file)
            out.writerow(header)
            out.writerows(rows)
        written.append(args.csv)
    if args.json:
        print(json.dumps(data))
        return
    table(data)
    for path in written:
        print(f"  wrote {path}")


def progress(args, iterable, total: int, what: str):
    """``iterable`` with a progress bar on stderr (none off a terminal or with ``--quiet``)."""
    from tqdm import tqdm

    return tqdm(iterable, total=total, desc=what, unit="", file=sys.stderr, leave=False,
                disable=True if getattr(args, "quiet", False) else None)


@contextmanager
def stages(args, what: str):
    """Show on stderr, while the block runs, each stage the solvers report
    (:mod:`linmstmm.stages`): on a terminal only, and not with ``--quiet``."""
    from tqdm import tqdm

    bar = tqdm(desc=what, unit=" stages", file=sys.stderr, leave=False,
               disable=True if getattr(args, "quiet", False) else None)

    def show(stage):
        bar.set_postfix_str(stage)
        bar.update()

    with bar, listening(show):
        yield
