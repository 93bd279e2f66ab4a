"""``linmstmm freqs --json`` and ``linmstmm fe --json`` agree on every model in models/.

Every ``*.toml`` under models/ that loads as a model is a case; other TOML
files there (the MLRS tube bundle, load files) are data, not models, and are
left out. The first ten frequencies (all, if there are fewer) must agree to 1e-7 relative and the
rigid-body mode counts must be equal.

The second launcher (models/launcher2/launcher2.toml, two closed loops) is also
checked deeper: its deduced structure is the one its comments describe, and its
first twenty frequencies agree with the FE route within the FE route's own error
estimate.
"""
from __future__ import annotations

import json
import subprocess
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

from linmstmm.model import load_model
from builders import BUNDLED_MODELS

ROOT = Path(__file__).resolve().parents[1]
AGREEMENT = 1e-7
LAUNCHER2 = ROOT / "models" / "launcher2" / "launcher2.toml"
#: A few units in the last place of a float64 frequency: the rounding of the
#: transfer-matrix result itself, which the FE estimate does not include.
ROUNDING = 2e-15


MODELS = BUNDLED_MODELS


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "linmstmm", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def solve(command: str, path: Path, *options) -> dict:
    """The ``--json`` object of ``linmstmm COMMAND PATH [OPTIONS]`` (by default the
    first ten frequencies)."""
    result = run(command, path, "--json", *options)
    assert result.returncode == 0, result.stderr
    return json.loads(result.stdout)


@lru_cache(maxsize=None)
def test_models_directory_has_models():
    assert len(MODELS) >= 3


@pytest.mark.parametrize("path", MODELS, ids=[str(p.relative_to(ROOT / "models")) for p in MODELS])
def test_freqs_and_fe_agree(path):
    freqs = solve("freqs", path)
    assert freqs["frequencies_hz"], "no frequencies"
    fe = solve("fe", path)
    assert fe["method"] == "fe" and fe["model"] == freqs["model"]
    assert fe["rigid_body_modes"] == freqs["rigid_body_modes"]
    assert len(fe["frequencies_hz"]) == len(freqs["frequencies_hz"])
    np.testing.assert_allclose(freqs["frequencies_hz"], fe["frequencies_hz"], rtol=AGREEMENT, atol=0)


def connected(model, a: str, b: str, without: str) -> bool:
    """Whether points ``a`` and ``b`` are joined by the model's elements other than ``without``."""
    links = [e.ports if e.kind == "rigid" else e.ends for e in model.elements if e.name != without]
    reached, frontier = {a}, [a]
    while frontier:
        point = frontier.pop()
        for ends in links:
            if point in ends:
                frontier += [p for p in ends if p not in reached]
                reached.update(ends)
    return b in reached


def test_launcher2_has_two_loops_with_beams_and_a_launcher_size_ubar():
    """Eight boundary ends and two loop cuts (elevating cylinder, firing tube):
    Ū_all of order 6·8 + 2·12 = 72; at least three beams, and a beam in each loop
    (its ends stay joined without it)."""
    result = run("check", LAUNCHER2, "--json")
    assert result.returncode == 0, result.stderr
    structure = json.loads(result.stdout)
    assert structure["ubar_order"] == 72 and len(structure["cuts"]) == 2
    model = load_model(LAUNCHER2)
    assert len(model.beams) >= 3
    in_loops = {beam.name for beam in model.beams if connected(model, *beam.ends, without=beam.name)}
    assert in_loops == {"barrel", "piston_rod", "tube_span"}


def test_launcher2_twenty_frequencies_within_fe_estimate():
    """``freqs --count 20`` against ``fe --count 20``: each relative difference within
    the FE route's own error estimate for that frequency, plus float64 rounding."""
    freqs = solve("freqs", LAUNCHER2, "--count", "20")
    fe = solve("fe", LAUNCHER2, "--count", "20")
    assert freqs["ubar_order"] == 72
    assert freqs["rigid_body_modes"] == fe["rigid_body_modes"] == 0
    assert len(freqs["frequencies_hz"]) == len(fe["frequencies_hz"]) == 20
    error = np.abs(np.divide(freqs["frequencies_hz"], fe["frequencies_hz"]) - 1.0)
    allowed = np.array(fe["error_estimate"]) + ROUNDING
    assert np.all(error <= allowed), np.c_[freqs["frequencies_hz"], fe["frequencies_hz"], error, allowed]
