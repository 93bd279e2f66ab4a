"""FRF sweep on a bundled model: receptance plot and resonance table.

    python scripts/frf_sweep.py [--model MODEL] [--point P] [--direction D] [--fmax HZ]
                                [--response-points P ...] [--plot FILE]

Defaults: the cantilever with tip mass (models/cantilever_tip_mass.toml), a
unit force along z at its tip, 0–200 Hz, response at the tip; the figure
goes to frf_sweep.png. Any bundled model works, e.g.
``--model models/mlrs/mlrs.toml --point muzzle --direction z --fmax 10``.
Same computation as ``linmstmm frf``.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from linmstmm.model import COMPONENTS, load_model  # noqa: E402
from linmstmm.plot import plot_frf  # noqa: E402
from linmstmm.studies import frf_study, frf_text  # noqa: E402


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default=str(ROOT / "models/cantilever_tip_mass.toml"))
    parser.add_argument("--point", default="tip", help="load point")
    parser.add_argument("--direction", default="z", choices=COMPONENTS)
    parser.add_argument("--fmax", type=float, default=200.0, help="top of the sweep, Hz")
    parser.add_argument("--response-points", nargs="+", default=None)
    parser.add_argument("--plot", default="frf_sweep.png", help="figure to write (PNG)")
    args = parser.parse_args(argv)

    model = load_model(args.model)
    result, summary = frf_study(model, args.point, args.direction, args.fmax,
                                response_points=args.response_points)
    plot_frf(result, args.plot, [f for f in summary["frequencies_hz"] if f <= args.fmax], summary["load_unit"],
             title=f"{model.name}: unit load {args.direction} at {args.point}")
    print(frf_text(result, summary))
    print(f"wrote {args.plot}")


if __name__ == "__main__":
    main()
