"""The ``linmstmm`` command line (every command and its JSON: ``docs/cli.md``).

One module per command (``linmstmm/cli/<command>.py``), each with one
``add_<command>_command(subparsers)``; :data:`COMMANDS` names them in the
order ``linmstmm -h`` shows them. A run imports the module of its own command
only (the help, all of them): what the other commands import is not the
start-up of this one. To add a command: write its module, add its name to
COMMANDS and give one example in COMMAND_EXAMPLES. The command modules use
the public API only (``linmstmm`` and the modules ``docs/api.md`` documents).

Exit status: 0 done; 1 the computation itself failed (clear message);
2 bad model file, bad option or impossible request (one line on stderr,
naming file, element and key; no traceback).
"""
from __future__ import annotations

import argparse
import importlib
import sys

from linmstmm import ModelError, __version__
from linmstmm.cli.common import ComputationError, UsageError

#: The commands, in the order ``linmstmm -h`` lists them: each is registered by
#: ``add_<name>_command(subparsers)`` of its module ``linmstmm.cli.<name>``.
COMMANDS = ["freqs", "check", "fe", "modes", "scan", "response", "frf", "sweep", "fit"]

#: Every command with one example on the bundled models (shown by ``linmstmm -h``).
COMMAND_EXAMPLES = {
    "freqs": "linmstmm freqs models/mlrs/mlrs.toml --count 10",
    "check": "linmstmm check models/mlrs/mlrs.toml",
    "fe": "linmstmm fe models/cantilever_tip_mass.toml --count 6",
    "modes": "linmstmm modes models/cantilever_tip_mass.toml --count 4 --plot modes",
    "scan": "linmstmm scan models/cantilever_tip_mass.toml --fmax 200 --plot scan.png",
    "response": "linmstmm response models/cantilever_tip_mass.toml models/loads/cantilever_step.toml",
    "frf": "linmstmm frf models/cantilever_tip_mass.toml --point tip --direction z --fmax 100",
    "sweep": "linmstmm sweep models/spring_mass_chain.toml --vary spring.k2.k[0]=500:2000:4:log --count 3",
    "fit": "linmstmm fit models/spring_mass_chain.toml models/measured/spring_mass_chain.csv --vary rigid.m2.mass=1:4",
}

class _Parser(argparse.ArgumentParser):
    """argparse that reports a bad option as one line instead of usage + exit."""

    def error(self, message):
        raise UsageError(f"{self.prog}: {message}")


def _examples() -> str:
    """The help's closing text: one example per command."""
    width = max(map(len, COMMAND_EXAMPLES))
    lines = [f"  {name:<{width}}  {example}" for name, example in COMMAND_EXAMPLES.items()]
    return "\n".join(["examples:", *lines, "",
                      "Most commands take --json for one JSON object on stdout.",
                      "'linmstmm COMMAND -h' lists a command's options; the guides are in docs/."])


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the commands in COMMANDS (each sets ``run`` to its function).

    Parameters
    ----------
    command : str or None
        The one command to register (its module alone is imported); None: all of them.

    Returns
    -------
    argparse.ArgumentParser
    """
    parser = _Parser(prog="linmstmm", description="Natural frequencies, mode shapes and modal response of\n"
                     "multi-rigid-flexible-body systems by the transfer matrix method for\n"
                     "multibody systems (MSTMM).", epilog=_examples(),
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"linmstmm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name in COMMANDS if command is None else [command]:
        module = importlib.import_module(f"linmstmm.cli.{name}")
        getattr(module, f"add_{name}_command")(sub)
    return parser


def main(argv=None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after the program name (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status: 0 done, 1 the computation failed, 2 bad input.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        if not argv:  # bare ``linmstmm``: what there is to do
            build_parser().print_help()
            return 0
        command = argv[0] if argv[0] in COMMANDS else None  # else: help, version or a misspelling
        args = build_parser(command).parse_args(argv)
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
