"""``linmstmm check MODEL``: validate a model and show its deduced transfer structure."""
from __future__ import annotations

from linmstmm import load_model
from linmstmm.cli.common import (
    add_model_argument,
    add_output_options,
    as_options,
    emit,
    writing,
)
from linmstmm.structure import describe
from linmstmm.topology import build_topology


def add_check_command(subparsers) -> None:
    """Register ``check MODEL [--root POINT] [--plot FILE] [--json]`` on ``subparsers``."""
    check = subparsers.add_parser(
        "check", help="validate a model and show its deduced transfer structure")
    add_model_argument(check)
    check.add_argument("--root", default=None, help="boundary point to use as the root")
    check.add_argument("--plot", default=None, metavar="FILE",
                       help="write the topology figure to FILE (PNG)")
    add_output_options(check)
    check.set_defaults(run=run_check)


def run_check(args) -> int:
    """Run ``linmstmm check``: print the structure (text or JSON), draw it with ``--plot``.

    Raises ModelError for a bad model file, a bad ``--root`` or a figure
    that cannot be written. Returns the exit status 0.
    """
    model = load_model(args.model)
    with as_options(model, "root"):
        topology = build_topology(model, root=args.root)
    report = describe(topology)
    if args.plot is not None:
        from linmstmm.plot_topology import (
            plot_topology,  # matplotlib only when asked for
        )

        with writing(model, "--plot", args.plot):
            plot_topology(topology, args.plot, title=model.name)

    def table(_):
        print(f"{model.name}: deduced transfer structure")
        if model.description:
            print(f"  {model.description}")
        print(report.to_text())

    emit(args, model, {"model": model.name, "description": model.description, **report.to_dict()}, table)
    return 0
