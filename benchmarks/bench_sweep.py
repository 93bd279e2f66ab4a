"""Parameter sweep of the launcher: a 20 x 20 grid, modes tracked by MAC, three ways of running it.

    python benchmarks/bench_sweep.py [--points 20] [--count 5] [--out reports]

The grid: the elevating mechanism's pitch stiffness (``spring.elevation.k[4]``)
and the turntable bearing's traverse stiffness (``spring.bearing.k[5]``), each
over a factor of 25 around the tuned value of models/mlrs/mlrs.toml, in
logarithmic steps: the two supports of the upper structure that the model
file calls honestly uncertain. The same sweep runs serially, in 2 local
processes and on a dask LocalCluster of 2 single-threaded worker processes,
each with the numpy engine and with the compiled kernels (loaded in every
process that runs steps); per engine the frequencies must be identical. Writes ``OUT/sweep.md`` (the command at
the top) and ``OUT/figures/sweep_launcher.png``. Not part of the test suite.
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from common import REPO, machine_facts

from linmstmm.determinant import BEAM_WEIGHT, KERNELS_PAY_FROM, carried_weight
from linmstmm.model import load_model
from linmstmm.sweep import Vary, grid, sweep
from linmstmm.topology import build_topology

MODEL = REPO / "models" / "mlrs" / "mlrs.toml"
#: (key, tuned value in the model file); each swept from value/5 to value*5.
PARAMETERS = (("spring.elevation.k[4]", 2.5e7), ("spring.bearing.k[5]", 3.0e7))
SPAN = 5.0
#: The engines measured: what a new process runs a short sweep of the launcher with, then the kernels.
ENGINES = ("numpy", "compiled")
#: Steps of the command-line sweeps (one range of ``spring.elevation.k[4]``) timed in new
#: processes, by each engine and by the default "auto", to show where "auto" takes the kernels.
COMMAND_STEPS = (20, 53, 100, 400)
#: (label, sweep options) of the runs of each engine; the cold ones must agree bitwise.
RUNS = (("serial", {}), ("2 processes", {"workers": 2}),
        ("dask LocalCluster, 2 workers", {"dask": "local", "workers": 2}),
        ("serial, warm starts", {"warm_start": True}))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=20, help="values per parameter")
    parser.add_argument("--count", type=int, default=5, help="frequencies per step")
    parser.add_argument("--out", default=str(REPO / "reports"), help="folder of sweep.md and figures/")
    args = parser.parse_args()
    command = "python benchmarks/bench_sweep.py" + "".join(f" {shlex.quote(a)}" for a in sys.argv[1:])

    model = load_model(MODEL)
    varies = [Vary(key, value / SPAN, value * SPAN, args.points, log=True) for key, value in PARAMETERS]
    steps, shape = grid(varies)
    runs = {}
    for engine in ENGINES:
        for label, options in RUNS:
            start = time.perf_counter()
            result = sweep(model, steps, count=args.count, shape=shape, progress=True, engine=engine, **options)
            runs[label, engine] = (result, time.perf_counter() - start)
            print(f"{label}, {engine}: {len(steps)} steps in {runs[label, engine][1]:.1f} s", flush=True)
    identical = all(_same(result, runs["serial", engine][0]) for (_, engine), (result, _) in runs.items()
                    if not result.warm_start)
    results = [runs[key][0] for key in runs]
    reference = runs["serial", ENGINES[0]][0].frequencies_hz_by_rank
    differences = [np.abs(result.frequencies_hz_by_rank / reference - 1) for result in results]

    out = Path(args.out)
    (out / "figures").mkdir(parents=True, exist_ok=True)
    figure = out / "figures" / "sweep_launcher.png"
    plot(results[0], varies, figure)
    commands = command_timings(args.count)
    write_report(out / "sweep.md", command, results[0], runs, (identical, np.nanmax(differences)), varies,
                 commands)
    print(f"wrote {out}/sweep.md and {figure}; runs identical: {identical}")


def _same(a, b) -> bool:
    """Whether two sweeps have bitwise the same frequencies and tracking."""
    return (np.array_equal(a.frequencies_hz_by_rank, b.frequencies_hz_by_rank, equal_nan=True)
            and np.array_equal(a.order, b.order))


def command_timings(count: int, rounds: int = 2) -> dict:
    """(steps, engine) -> (best wall time s of ``rounds``, the engine the sweep reported):
    ``linmstmm sweep`` of the launcher over COMMAND_STEPS steps of one range, each in a new
    process (start-up, loading and kernels included), by "auto", "numpy" and "compiled",
    taken in turn in each round."""
    timings = {}
    for _ in range(rounds):
        for steps in COMMAND_STEPS:
            low, high = PARAMETERS[0][1] / SPAN, PARAMETERS[0][1] * SPAN
            for engine in ("auto", *ENGINES):
                start = time.perf_counter()
                run = subprocess.run([sys.executable, "-m", "linmstmm", "sweep", str(MODEL), "--vary",
                                      f"{PARAMETERS[0][0]}={low}:{high}:{steps}:log", "--count", str(count),
                                      "--engine", engine, "--json"], capture_output=True, text=True, check=True)
                seconds = time.perf_counter() - start
                best = min(seconds, timings.get((steps, engine), (np.inf, ""))[0])
                timings[steps, engine] = (best, json.loads(run.stdout)["engine"])
                print(f"command, {steps} steps, {engine}: {seconds:.2f} s", flush=True)
    return timings


def write_report(path, command, result, runs, agreement, varies, commands) -> None:
    """The Markdown report: setup, throughput, identity of the runs, what the default engine
    picks (``commands``, :func:`command_timings`), what tracking did.

    runs : (runner, engine) -> (SweepResult, wall time s); agreement : (whether the runs of
    each engine are bitwise identical, largest relative difference between the engines)."""
    identical, difference = agreement
    steps = len(result.values)
    swapped = int(np.sum(np.any(result.order != np.arange(result.order.shape[1]), axis=1)))
    facts = machine_facts()
    weight = launcher_weight()
    load = ", ".join(f"{v:.1f}" for v in os.getloadavg())
    lines = [
        "# Parameter sweep of the launcher",
        "",
        (f"Generated by `{command}` on {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; "
        f"{facts['cores']} cores ({facts['cpu']}), shared with other work (load average {load} "
        "over 1, 5, 15 min when the report was written), so absolute times and speed-ups are loose."),
        "",
        f"Model `models/mlrs/mlrs.toml`, a {' x '.join(map(str, result.shape))} grid "
        f"(logarithmic steps): "
        + "; ".join(f"`{v.key}` {v.start:.3g} … {v.stop:.3g}" for v in varies)
        + f". Lowest {result.order.shape[1]} elastic frequencies per step; each step is one "
        "`mode_shapes` solve (its frequencies are those of `natural_frequencies`; its shapes serve "
        "the MAC tracking), from a cold start. Engines: `numpy` (the bits of `linmstmm freqs` in a "
        "new process) and `compiled` (the numba kernels, loaded in every process that runs "
        "steps: the time includes that; what the default `auto` takes for a sweep this long, "
        "below); the last run of each starts every step from its neighbour's frequencies "
        "(`warm_start=True`).",
        "",
        "| run | engine | wall time | solves per second | speed-up over serial numpy |",
        "|---|---|---:|---:|---:|",
    ]
    serial = next(iter(runs.values()))[1]
    lines += [f"| {label} | {engine} | {seconds:.1f} s | {steps / seconds:.1f} | {serial / seconds:.2f} |"
              for (label, engine), (_, seconds) in runs.items()]
    if os.getloadavg()[0] >= facts["cores"]:
        lines += ["", ("Other work held the cores during this run (1-min load average at or above the "
                       "number of cores, and these runs are niced), so the extra processes found no idle "
                       "core: the speed-ups measure that contention, not what the parallel runs give on an "
                       "idle machine.")]
    lines += [
        "",
        (f"Frequencies and tracking identical in the three runs of each engine: "
         f"**{'yes' if identical else 'NO'}** (bitwise, `numpy.array_equal`). Between the engines, "
         f"and between warm and cold starts, the frequencies differ by at most {difference:.1e} "
         "(relative): rounding. A warm start begins each step's root search at the frequencies of "
         "the step it is tracked from, so a step waits for that one: serial only here."),
        "",
        "## What the default engine picks",
        "",
        ("`engine=\"auto\"` (the default of `sweep` and of the command) loads the compiled kernels "
         "where the steps times the frequencies per step times the elements carried one at a time, "
         f"each beam counted {BEAM_WEIGHT} times, reach {KERNELS_PAY_FROM:,} "
         "(`linmstmm.determinant.kernels_pay`; the launcher counts "
         f"{weight}, so at {result.order.shape[1]} frequencies a step from "
         f"{-(-KERNELS_PAY_FROM // (weight * result.order.shape[1]))} steps), "
         "and they are compiled on the machine; else the numpy carry. "
         "`linmstmm sweep` of the launcher over one range of "
         f"`{PARAMETERS[0][0]}`, lowest {result.order.shape[1]}, each run a new process "
         "(start-up, loading and the kernels' start-up included), best of 2; in brackets the "
         "engine the sweep reported:"),
        "",
        "| steps | auto (the default) | numpy | compiled |",
        "|---:|---:|---:|---:|",
        *(f"| {steps} | {commands[steps, 'auto'][0]:.2f} s ({commands[steps, 'auto'][1]}) | "
          f"{commands[steps, 'numpy'][0]:.2f} s | {commands[steps, 'compiled'][0]:.2f} s |"
          for steps in COMMAND_STEPS),
        "",
        "## What tracking did",
        "",
        (f"Steps where some column follows a mode of another rank than its own: {swapped} of {steps}. "
        f"Smallest MAC of a column against the same column at its neighbouring step: "
        f"{np.nanmin(result.tracking_mac):.3f}."),
        "",
        ("Each step is tracked from its neighbour one step back along the last key (the first "
        "step of a row from the row before). On a grid of two values the identity of modes that "
        "veer is path-dependent: a path passing close to where two frequencies nearly meet sees "
        "the shapes swap (and the columns follow the swap), one passing further away sees them "
        "turn gradually (and the columns stay with their ranks), so neighbouring rows can resolve "
        "a veering differently and a panel's colours jump between rows; along a row (the last "
        "panel) the columns follow the tracking path."),
        "",
        "| column | frequency range [Hz] | ranks it takes | smallest MAC to its neighbour |",
        "|---:|---:|---|---:|",
    ]
    for c in range(result.order.shape[1]):
        f = result.frequencies_hz[:, c]
        ranks = ", ".join(str(r + 1) for r in sorted(set(result.order[:, c].tolist())))
        lines.append(f"| {c + 1} | {np.nanmin(f):.4f} … {np.nanmax(f):.4f} | {ranks} | "
                     f"{np.nanmin(result.tracking_mac[:, c]):.3f} |")
    lines += ["", "![tracked frequencies over the grid](figures/sweep_launcher.png)", ""]
    with open(path, "w") as stream:
        stream.write("\n".join(lines))


def launcher_weight() -> int:
    """The launcher's elements carried one at a time, each beam BEAM_WEIGHT times, as
    :func:`linmstmm.determinant.kernels_pay` counts them."""
    return carried_weight(build_topology(load_model(MODEL)))


def plot(result, varies, path) -> None:
    """One panel per tracked column: frequency (Hz) over the grid, log axes; the last panel
    the columns along the second key (the way tracking goes) at the middle of the first,
    tracked and by rank."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    count = result.order.shape[1]
    x, y = (v.values() for v in varies)
    figure = Figure(figsize=(12, 7), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(2, (count + 2) // 2, squeeze=False).ravel()
    tracked = result.frequencies_hz.reshape(x.size, y.size, count)
    for c in range(count):
        panel = axes[c]
        image = panel.contourf(y, x, tracked[:, :, c], levels=14, cmap="viridis")
        figure.colorbar(image, ax=panel, label="Hz")
        panel.set_xscale("log")
        panel.set_yscale("log")
        panel.set_title(f"column {c + 1}", fontsize=9)
        panel.set_xlabel(varies[1].key + " [N m/rad]", fontsize=8)
        panel.set_ylabel(varies[0].key + " [N m/rad]", fontsize=8)
    lines = axes[count]
    middle = x.size // 2
    by_rank = result.frequencies_hz_by_rank.reshape(x.size, y.size, count)
    for c in range(count):
        lines.plot(y, tracked[middle, :, c], "-", color=f"C{c}", lw=2, label=f"column {c + 1}")
        lines.plot(y, by_rank[middle, :, c], ":", color="k", lw=0.8, label="by rank" if c == 0 else None)
    lines.set_xscale("log")
    lines.set_xlabel(varies[1].key + " [N m/rad]", fontsize=8)
    lines.set_ylabel("natural frequency [Hz]")
    lines.set_title(f"a tracking path: {varies[0].key} = {x[middle]:.3g}", fontsize=9)
    lines.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.0, 0.5))
    for panel in axes[count + 1:]:
        panel.set_visible(False)
    figure.suptitle("MLRS-style launcher: lowest elastic frequencies, columns following mode shapes (MAC)")
    figure.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
