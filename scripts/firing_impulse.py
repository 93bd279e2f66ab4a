"""Response of the MLRS-style launcher to the firing of a rocket: plot and peak table.

    python scripts/firing_impulse.py [--model MODEL] [--loads LOADS] [--plot FILE]
                                     [--quantity displacement|velocity|acceleration]

Defaults: models/mlrs/mlrs.toml with models/loads/mlrs_firing.toml (the
detent-release impulse along the tube axis at the breech end of tube 1 and
the jet reaction on the breech; the file states its assumptions). Writes the
response histories of the file's output points to FILE (default
mlrs_firing_response.png) and prints the peak responses. Same computation as
``linmstmm response MODEL LOADS --plot FILE``.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from linmstmm.model import load_model  # noqa: E402
from linmstmm.plot import plot_response  # noqa: E402
from linmstmm.response import load_loads, respond  # noqa: E402
from linmstmm.studies import peak_responses, peaks_text  # noqa: E402


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default=str(ROOT / "models/mlrs/mlrs.toml"))
    parser.add_argument("--loads", default=str(ROOT / "models/loads/mlrs_firing.toml"))
    parser.add_argument("--plot", default="mlrs_firing_response.png", help="figure to write (PNG)")
    parser.add_argument("--quantity", choices=("displacement", "velocity", "acceleration"),
                        default="displacement")
    args = parser.parse_args(argv)

    model = load_model(args.model)
    case = load_loads(args.loads, model)
    start = time.perf_counter()
    result = respond(model, case)
    seconds = time.perf_counter() - start
    plot_response(result, args.plot, args.quantity, title=f"{model.name}: firing ({Path(args.loads).name})")
    print(f"{model.name}: {len(case.loads)} loads, {result.elastic_modes} elastic modes, "
          f"{result.times.size} time steps to {result.times[-1]:g} s, solved in {seconds:.2f} s")
    print(peaks_text(result.points, *peak_responses(result, args.quantity), args.quantity))
    print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
