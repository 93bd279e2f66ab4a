"""Hundreds of random models with the extremes against the FE route.

    python benchmarks/random_vs_fe.py --seeds 0 300 [--count 10] [--referee] [--report reports/random_vs_fe.md]

For each seed of ``tests/varied_models.py`` (slender beams down to A = 1e-5 m²,
bending stiffnesses up to 1e12 apart between the planes, massless dangling
points, bodies held by one zero-length spring, other units, clamped / pinned /
free ends) it solves the lowest ``--count`` frequencies with
``natural_frequencies`` and with ``fe_frequencies`` (refined until its own
error estimate is below rtol 1e-9, or its mesh cap) and checks:

* the same number of rigid-body modes and of elastic frequencies (none from
  either for a model with only massless dangling points to move);
* each frequency within the FE route's own error: |f / f_FE − 1| <=
  max(TOLERANCE_FACTOR × FE error estimate, FLOOR);
* for a model written in other units, the same frequencies as its SI copy by
  ``natural_frequencies`` to UNITS_AGREEMENT;
* with ``--referee``, every frequency the two routes give more than REFEREE_GAP
  apart, agreeing or not, against meshes finer than the refinement's cap
  (:func:`fine_mesh_reference`): which route is off, where FE's own estimate at
  its cap (about 5e-4 at 40 modes of a beam with Ip ≫ J) leaves it open.

Every disagreement and error is listed with its seed; the report (Markdown)
gives counts, the disagreements and timings. Not part of the test suite.
"""
from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np
from common import REPO

sys.path.insert(0, str(REPO / "tests"))
from varied_models import UNITS, in_units, varied_model  # noqa: E402

from linmstmm.fe import fe_frequencies  # noqa: E402
from linmstmm.solve import natural_frequencies  # noqa: E402
from linmstmm.wording import counted  # noqa: E402

#: A frequency agrees where it is within this many times FE's own error estimate ...
TOLERANCE_FACTOR = 3.0
#: ... or within this (relative), whichever is larger (FE's estimate can be rounding).
FLOOR = 1e-9
#: A model in other units must give its SI copy's frequencies to this (relative).
UNITS_AGREEMENT = 1e-9
#: The report counts the models whose FE error estimates are all below this.
TIGHT = 1e-8


def compare(seed: int, count: int, referee: bool = False) -> dict:
    """One model: its variety, timings, verdict ("agree", "disagree" or "error"), what
    differs and, with ``referee``, the frequencies :func:`refereed` checked."""
    model, variety = varied_model(seed)
    row = {"seed": seed, "variety": variety.label(), "family": variety.family, "problems": []}
    try:
        started = time.perf_counter()
        ours = natural_frequencies(model, count)
        row["mstmm_s"] = time.perf_counter() - started
    except Exception as error:  # a sweep reports every failure and goes on
        row["problems"].append(f"MSTMM {type(error).__name__}: {error}")
        ours = None
    try:
        started = time.perf_counter()
        theirs = fe_frequencies(model, count=count)
        row["fe_s"] = time.perf_counter() - started
    except Exception as error:
        row["problems"].append(f"FE {type(error).__name__}: {error}")
        theirs = None
    if ours is None or theirs is None:
        row["verdict"] = "error"
        return row
    row["problems"] += differences(ours, theirs)
    if variety.units != UNITS[0][0]:
        row["problems"] += unit_differences(model, variety.units, ours.frequencies_hz, count)
    row["elastic"] = len(theirs.frequencies_hz)
    row["fe_error"] = float(np.max(theirs.error_estimate, initial=0.0))
    row["difference"] = float(np.max(np.abs(ours.frequencies_hz / theirs.frequencies_hz - 1), initial=0.0)) \
        if len(ours.frequencies_hz) == len(theirs.frequencies_hz) else np.inf
    row["verdict"] = "disagree" if row["problems"] else "agree"
    if referee:
        row["refereed"] = refereed(model, ours.frequencies_hz, theirs.frequencies_hz)
    return row


def differences(ours, theirs) -> list[str]:
    """What differs between an MSTMM and an FE result of the same model."""
    problems = []
    if ours.rigid_body_modes != theirs.rigid_body_modes:
        problems.append(f"rigid-body modes {ours.rigid_body_modes} (MSTMM) vs {theirs.rigid_body_modes} (FE)")
    a, b, error = ours.frequencies_hz, theirs.frequencies_hz, theirs.error_estimate
    if len(a) != len(b):
        problems.append(f"{len(a)} elastic frequencies (MSTMM) vs {len(b)} (FE); "
                        f"MSTMM {np.array2string(a, precision=6)}, FE {np.array2string(b, precision=6)}"
                        + (f"; MSTMM note: {ours.note}" if ours.note else "")
                        + (f"; FE note: {theirs.note}" if theirs.note else ""))
        return problems
    off = np.abs(a / b - 1)
    bad = np.flatnonzero(off > np.maximum(TOLERANCE_FACTOR * error, FLOOR))
    problems += [f"f{i + 1}: MSTMM {a[i]:.10g} Hz, FE {b[i]:.10g} Hz ({off[i]:.1e} off, FE error "
                 f"{error[i]:.1e})" for i in bad]
    return problems


def unit_differences(model, units: str, frequencies, count: int) -> list[str]:
    """Differences from the same model converted back to SI (a failure of the SI copy's
    solve among them)."""
    _, length, mass = next(u for u in UNITS if u[0] == units)
    try:
        si = natural_frequencies(in_units(model, 1 / length, 1 / mass), count).frequencies_hz
    except Exception as error:  # a sweep reports every failure and goes on
        return [f"the SI copy raised: MSTMM {type(error).__name__}: {error}"]
    if len(si) != len(frequencies):
        return [f"{len(frequencies)} frequencies in {units}, {len(si)} in SI"]
    off = float(np.max(np.abs(frequencies / si - 1), initial=0.0))
    return [f"{units} differs from SI by {off:.1e}"] if off > UNITS_AGREEMENT else []


#: With --referee, frequencies the two routes give more than this apart (relative) are
#: checked against ...
REFEREE_GAP = 1e-7
#: ... fixed meshes of these many elements per beam (fe_frequencies' cap and two finer).
REFEREE_MESHES = (1024, 2048, 4096)


def fine_mesh_reference(model, count: int):
    """The lowest ``count`` frequencies from fixed meshes of REFEREE_MESHES, and the size
    of their last extrapolation step.

    λ is extrapolated rank by rank over these meshes alone: h² out of each two, then h⁴
    out of the two results (Romberg). The coarse meshes of ``fe_frequencies``'
    refinement are left out: there the slow torsion waves of a beam with Ip ≫ J
    (linear elements, error (kh)²/24) lie above modes they lie below on finer meshes,
    and an extrapolation by rank mixes the two (varied 218's 40th: 6.4e-5 off, inside
    its estimate of 5.1e-4; these meshes give the transfer matrices' root to 4e-12).

    Returns
    -------
    hz : (count,) float
        The extrapolated frequencies, Hz.
    step : (count,) float
        |f(h²) / f(h⁴) − 1| of the finest meshes: how far the last step moved each.
    """
    lam = np.array([(2 * np.pi * fe_frequencies(model, count=count, elements_per_beam=n, estimate_error=False)
                     .frequencies_hz[:count]) ** 2 for n in REFEREE_MESHES])
    h2 = lam[1:] + (lam[1:] - lam[:-1]) / 3
    h4 = h2[1] + (h2[1] - h2[0]) / 15
    return np.sqrt(h4) / (2 * np.pi), np.abs(np.sqrt(h2[1] / h4) - 1)


def refereed(model, ours, theirs) -> list[dict]:
    """Each frequency that MSTMM (``ours``, Hz) and FE (``theirs``) give more than
    REFEREE_GAP apart, against :func:`fine_mesh_reference`: rank, both routes' relative
    differences from it, its last step, and whether MSTMM lies within
    max(TOLERANCE_FACTOR × that step, FLOOR) of it."""
    if len(ours) != len(theirs):
        return []
    apart = np.flatnonzero(np.abs(ours / theirs - 1) > REFEREE_GAP)
    if not apart.size:
        return []
    reference, step = fine_mesh_reference(model, int(apart[-1]) + 1)
    return [{"rank": int(i), "hz": float(reference[i]), "step": float(step[i]),
             "mstmm": float(ours[i] / reference[i] - 1), "fe": float(theirs[i] / reference[i] - 1),
             "mstmm_holds": bool(abs(ours[i] / reference[i] - 1) <= max(TOLERANCE_FACTOR * step[i], FLOOR))}
            for i in apart]


#: What is known of a seed that disagreed, found by hand after a run (printed under the
#: seed's line whenever it disagrees again). Seeds 218 in km and 248 in mm-t-s were the FE
#: route's rigid motions mixing the units (fixed, tests/test_fe_units.py); seed 98 was the
#: FE eigensolver's Rayleigh quotients taken from deflated vectors (fixed, tests/test_fe_rounding.py).
DIAGNOSES: dict[int, str] = {}


#: Known limits the agreement check does not reach.
KNOWN_LIMITS = ("Beams are cut into pieces by their bending waves (βL) alone, so off the real axis a "
                "shaft whose polar inertia is far above its torsion constant (Ip/J = 4.3e11 in seed 4) "
                "loses log|det| on the counting contours in both engines (2 in 60 at 0.3 + 0.3i rad/s "
                "against mpmath). Cutting by the axial and torsional waves too (|Im kL| <= 1) restores "
                "1e-13 there, but made the numpy carry's solve of that model take minutes (its contours "
                "reach |Im ω| = 14: 3000 pieces), and was not kept. At 10 modes the counts still come out "
                "right on every model here; far out on a contour, where cos kL overflows, both engines "
                "answer NaN and the counts step round the point. At 40 modes some models with a beam of "
                "Ip/J from 2e7 up raise instead (not diagnosed further): a count the phase of det Ū_all "
                "turns too fast for, or a contour where det is not finite (reported as an undeflated "
                "indeterminate constraint; seed 4 at 0.262 + 0.152i rad/s: det exactly 0 within the "
                "40-mode solve, log|det| 38.4 compiled and 40.0 by numpy in a fresh process). Which "
                "models raise depends on the engine (seed 13, Ip/J 2.2e7: numpy raises, compiled solves).")


def report(rows: list[dict], command: str, seconds: float) -> str:
    """The Markdown report."""
    verdicts = Counter(row["verdict"] for row in rows)
    lines = [f"`{command}`", "", "# Random models with the extremes against the FE route", "",
             f"{len(rows)} models of `tests/varied_models.py` (seeds {rows[0]['seed']}–{rows[-1]['seed']}): "
             f"**{verdicts['agree']} agree**, {verdicts['disagree']} disagree, {verdicts['error']} raised. "
             f"Agreement: the same rigid-body and elastic counts, every frequency within "
             f"max({TOLERANCE_FACTOR:g} × FE's error estimate, {FLOOR:g}); models in other units also "
             f"give their SI copy's frequencies to {UNITS_AGREEMENT:g}. Wall time {seconds:.0f} s.", "",
             f"Of the models that agree, {sum(r['verdict'] == 'agree' and r['fe_error'] <= TIGHT for r in rows)} "
             f"are checked to FE errors of {TIGHT:g} or less throughout; in the others FE's own estimate "
             f"(up to {max((r['fe_error'] for r in rows if r['verdict'] == 'agree'), default=0):.1e}) "
             "bounds the check.", "",
             "## By family", "", "| family | models | agree | largest difference | largest FE error |",
             "|---|---|---|---|---|"]
    for family in sorted({row["family"] for row in rows}):
        group = [row for row in rows if row["family"] == family]
        done = [row for row in group if "difference" in row]
        lines.append(f"| {family} | {len(group)} | {sum(r['verdict'] == 'agree' for r in group)} | "
                     f"{max((r['difference'] for r in done), default=0):.1e} | "
                     f"{max((r['fe_error'] for r in done), default=0):.1e} |")
    lines += ["", "Models with only massless dangling points to move: "
              f"{sum(r['family'] == 'dangling only' and r.get('elastic') == 0 for r in rows)} of "
              f"{sum(r['family'] == 'dangling only' for r in rows)} give no elastic frequency from either route.",
              "", "## Disagreements and errors", ""]
    failed = [row for row in rows if row["verdict"] != "agree"]
    for row in failed:
        lines.append(f"* seed {row['seed']} ({row['variety']}): " + "; ".join(row["problems"]))
        if row["seed"] in DIAGNOSES:
            lines.append(f"  *Known:* {DIAGNOSES[row['seed']]}")
    lines += [] if failed else ["None."]
    lines += referee_section(rows)
    lines += ["", "## Known limits", "", KNOWN_LIMITS]
    lines += ["", "## Timings (s per model)", "", "| route | median | 90 % | max |", "|---|---|---|---|"]
    for key, label in (("mstmm_s", "natural_frequencies"), ("fe_s", "fe_frequencies (refined)")):
        times = np.array([row[key] for row in rows if key in row])
        if times.size:
            lines.append(f"| {label} | {np.median(times):.3f} | {np.quantile(times, 0.9):.3f} | {times.max():.2f} |")
    return "\n".join(lines) + "\n"


def referee_section(rows: list[dict]) -> list[str]:
    """The report's lines on the frequencies :func:`refereed` checked (none without
    --referee)."""
    checked = [(row, item) for row in rows for item in row.get("refereed", ())]
    if not any("refereed" in row for row in rows):
        return []
    lines = ["", "## Against finer meshes", "",
             f"{counted(len(checked), 'frequency', 'frequencies')} of "
             f"{counted(len({row['seed'] for row, _ in checked}), 'model')} differ by more than "
             f"{REFEREE_GAP:g} between the routes; each against fixed meshes of "
             f"{', '.join(map(str, REFEREE_MESHES))} elements per beam, λ extrapolated rank by rank over these "
             f"alone (h², then h⁴). MSTMM lies within max({TOLERANCE_FACTOR:g} × the last step, {FLOOR:g}) of "
             f"it for {sum(item['mstmm_holds'] for _, item in checked)} of them.", ""]
    if checked:
        lines += ["| seed | mode | fine meshes (Hz) | last step | MSTMM − fine | FE − fine | MSTMM holds |",
                  "|---|---|---|---|---|---|---|"]
        lines += [f"| {row['seed']} | f{item['rank'] + 1} | {item['hz']:.10g} | {item['step']:.1e} | "
                  f"{item['mstmm']:+.1e} | {item['fe']:+.1e} | {'yes' if item['mstmm_holds'] else '**no**'} |"
                  for row, item in checked]
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs=2, default=(0, 300), metavar=("FIRST", "STOP"))
    parser.add_argument("--count", type=int, default=10)
    parser.add_argument("--referee", action="store_true",
                        help=f"check frequencies more than {REFEREE_GAP:g} apart against finer meshes")
    parser.add_argument("--report", default=None, help="write the Markdown report here")
    args = parser.parse_args(argv)
    started, rows = time.perf_counter(), []
    for seed in range(*args.seeds):
        rows.append(compare(seed, args.count, args.referee))
        row = rows[-1]
        checked = "; ".join(f"f{item['rank'] + 1}: MSTMM {item['mstmm']:+.1e}, FE {item['fe']:+.1e} of finer meshes"
                            for item in row.get("refereed", ()))
        print(f"{seed:4d} {row['verdict']:8s} {row.get('mstmm_s', np.nan):7.3f} {row.get('fe_s', np.nan):7.3f} "
              f"{row['variety']} {'; '.join(row['problems'] + ([checked] if checked else []))}", flush=True)
    command = "python benchmarks/random_vs_fe.py " + " ".join(argv if argv is not None else sys.argv[1:])
    text = report(rows, command.strip(), time.perf_counter() - started)
    if args.report:
        Path(args.report).write_text(text)
    print(text)
    return 0 if all(row["verdict"] == "agree" for row in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
