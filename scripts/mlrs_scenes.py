"""Natural frequencies of the MLRS-style launcher in every firing scene, as a table.

    python scripts/mlrs_scenes.py [--count N] [--salvo] [--tubes 1 6 13 18] [MODEL]

Scene l: tube l is the flexible one, the other 17 are lumped into the
cradle (linmstmm.scenes). --salvo: tubes fire in slot order, so the rockets
of tubes 1 … l−1 are gone when tube l fires (a lighter cradle).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from linmstmm.model import load_model  # noqa: E402
from linmstmm.scenes import bundle_beside, salvo, scene_sweep  # noqa: E402


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", nargs="?", default=str(ROOT / "models/mlrs/mlrs.toml"))
    parser.add_argument("--count", type=int, default=6, help="frequencies per scene (default 6)")
    parser.add_argument("--salvo", action="store_true", help="rockets of tubes 1 … l−1 already fired")
    parser.add_argument("--tubes", type=int, nargs="+", help="scenes to compute (default: all)")
    args = parser.parse_args(argv)

    start = time.perf_counter()
    model = load_model(args.model)
    bundle = bundle_beside(model)
    load_seconds = time.perf_counter() - start
    tubes = args.tubes or list(bundle.slots)
    start = time.perf_counter()
    results = scene_sweep(model, args.count, tubes, salvo if args.salvo else None, bundle)
    sweep_seconds = time.perf_counter() - start

    title = "salvo in slot order (rockets 1 … l-1 fired)" if args.salvo else "all other tubes loaded"
    print(f"Natural frequencies (Hz) per firing scene, {title}")
    print(f"{'tube':>4} {'row':>3} {'col':>3}  " + " ".join(f"{f'f{i + 1}':>7}" for i in range(args.count)))
    for tube, frequencies in results:
        row, column = bundle.grid(tube)
        print(f"{tube:4d} {row:3d} {column:3d}  " + " ".join(f"{f:7.4f}" for f in frequencies))
    table = np.array([frequencies for _, frequencies in results])
    spread = (table.max(axis=0) - table.min(axis=0)) / table.mean(axis=0)
    print(f"{'spread':<14}" + " ".join(f"{s:7.1e}" for s in spread))
    print("(spread: (max - min) / mean over the scenes)")
    print(f"\nload + validate model and bundle once: {load_seconds * 1e3:.1f} ms; "
          f"{len(tubes)} scenes solved in {sweep_seconds:.2f} s "
          f"({sweep_seconds / len(tubes):.2f} s per scene)")


if __name__ == "__main__":
    main()
