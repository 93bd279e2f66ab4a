"""The ``linmstmm`` command line (every command and its JSON: ``docs/cli.md``).

Exit status: 0 done; 1 the computation itself failed (clear message);
2 bad model file, bad option or impossible request (one line on stderr,
naming file, element and key; no traceback).
"""
from __future__ import annotations

import argparse
import json
import math
import sys

from linmstmm import __version__
from linmstmm.model import ModelError, load_model
from linmstmm.damped_command import add_damped_option
from linmstmm.fe_command import add_fe_command
from linmstmm.mode_commands import add_mode_commands
from linmstmm.structure import add_check_command


class UsageError(Exception):
    """A bad option or an impossible request (exit status 2)."""


class ComputationError(Exception):
    """The computation could not deliver what was asked (exit status 1)."""


class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad option as one line instead of usage + exit."""

    def error(self, message):
        raise UsageError(f"{self.prog}: {message}")


def _positive_int(text):
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value


def _positive_float(text):
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {text}")
    return value


def _add_request_options(parser):
    parser.add_argument("model", help="model file (TOML, see model-format.md)")
    parser.add_argument("--count", type=_positive_int, default=None,
                        help="the lowest N elastic frequencies (default 10 unless --fmax)")
    parser.add_argument("--fmax", type=_positive_float, default=None,
                        help="all elastic frequencies up to HZ")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")


#: Every command with one example on the bundled models (shown by ``linmstmm -h``).
COMMAND_EXAMPLES = {
    "freqs": "linmstmm freqs models/mlrs/mlrs.toml --count 10",
    "check": "linmstmm check models/mlrs/mlrs.toml",
    "fe": "linmstmm fe models/cantilever_tip_mass.toml --count 6",
    "modes": "linmstmm modes models/cantilever_tip_mass.toml --count 4 --plot modes",
    "scan": "linmstmm scan models/cantilever_tip_mass.toml --fmax 200 --plot scan.png",
    "response": "linmstmm response models/cantilever_tip_mass.toml models/loads/cantilever_step.toml",
    "frf": "linmstmm frf models/cantilever_tip_mass.toml --point tip --direction z --fmax 100",
}


def _examples() -> str:
    """The help's closing text: one example per command."""
    width = max(map(len, COMMAND_EXAMPLES))
    lines = [f"  {name:<{width}}  {example}" for name, example in COMMAND_EXAMPLES.items()]
    return "\n".join(["examples:", *lines, "",
                      "Most commands take --json for one JSON object on stdout.",
                      "'linmstmm COMMAND -h' lists a command's options; the guides are in docs/."])


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command (each sets ``run`` to its function)."""
    parser = _Parser(prog="linmstmm", description="Natural frequencies, mode shapes and modal response of\n"
                     "multi-rigid-flexible-body systems by the transfer matrix method for\n"
                     "multibody systems (MSTMM).", epilog=_examples(),
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"linmstmm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    freqs = sub.add_parser("freqs", help="natural frequencies by the transfer matrix method")
    _add_request_options(freqs)
    freqs.add_argument("--digits", type=_positive_int, default=None,
                       help="significant digits wanted (above 14 the mpmath path is used)")
    freqs.add_argument("--root", default=None, help="boundary point to use as the root")
    freqs.add_argument("--engine", choices=("auto", "numpy", "compiled"), default="auto",
                       help="how det Ū_all is evaluated: the numpy carry, or numba-compiled kernels "
                            "(about 5x cheaper per evaluation, 0.5-1.5 s to start in a new process); "
                            "auto: numpy in a new process")
    freqs.set_defaults(run=_run_freqs)
    add_damped_option(freqs)
    add_check_command(sub)
    add_fe_command(sub)
    add_mode_commands(sub)
    return parser


def _request(args):
    """(count, fmax) as the solver wants them: --count defaults to 10 without --fmax."""
    count = args.count
    if count is None and args.fmax is None:
        count = 10
    return count, args.fmax


def _print_frequency_table(title, result):
    print(f"{title}")
    print(f"  rigid-body modes: {result['rigid_body_modes']}")
    if "ubar_order" in result:
        print(f"  order of Ubar_all: {result['ubar_order']}")
    if result.get("precision", "float64") != "float64":
        print(f"  precision: {result['precision']}")
    hz = result.get("frequencies_hz_text") or [f"{f:.12g}" for f in result["frequencies_hz"]]
    rad_s = result.get("omega_rad_s_text") or [f"{2 * 3.141592653589793 * f:.12g}" for f in result["frequencies_hz"]]
    width = max([20] + [len(text) for text in hz + rad_s])
    print(f"  {'mode':>4}  {'f [Hz]':>{width}}  {'omega [rad/s]':>{width}}")
    for index, (f, omega) in enumerate(zip(hz, rad_s), start=1):
        print(f"  {index:>4}  {f:>{width}}  {omega:>{width}}")
    print(f"  solve time: {result['seconds'] * 1e3:.2f} ms")
    if result.get("note"):
        print(f"  note: {result['note']}")


def _run_freqs(args):
    from linmstmm.solve import natural_frequencies

    model = load_model(args.model)
    count, fmax = _request(args)
    result = natural_frequencies(model, count=count, fmax=fmax, digits=args.digits, root=args.root,
                                 engine=args.engine)
    data = result.to_dict()
    if args.json:
        print(json.dumps(data))
    else:
        _print_frequency_table(f"{model.name}: natural frequencies (MSTMM)", data)
    return 0


def main(argv=None) -> int:
    """Run the command line; return the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        if not argv:  # bare ``linmstmm``: what there is to do
            build_parser().print_help()
            return 0
        args = build_parser().parse_args(argv)
        return args.run(args)
    except (ModelError, UsageError) as error:
        print(f"linmstmm: error: {error}", file=sys.stderr)
        return 2
    except (ComputationError, RuntimeError) as error:
        print(f"linmstmm: computation failed: {error}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into head & co.: stop quietly
        sys.stderr.close()
        return 0
