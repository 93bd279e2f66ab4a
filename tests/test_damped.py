"""Damped natural frequencies (linmstmm.damped, ``freqs --damped``) against independent solutions.

* the two-mass chain with a dashpot between the masses: the quadratic
  eigenproblem (K + sC + s²M) x = 0 of its hand-written matrices, and the FE
  route's (:func:`linmstmm.fe.damped_roots`), exact for springs and bodies;
* Rayleigh damping alone: the closed form ζ_k = α/(2ω_k) + βω_k/2 about the
  undamped ω_k (ω_n = ω_k), on a beam with a tip mass;
* the launcher with dashpots in its jacks, and random models (free-floating,
  loops, a ring) with dashpots and Rayleigh damping: the FE route on refined meshes.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
from builders import cantilever_with_tip_dashpot, spring_mass_chain
from random_models import random_model
from test_forced import (
    C_HAND,
    K_HAND,
    M_HAND,
    command,
    dashpot_chain,
    relative,
    with_dashpots,
)

from linmstmm.damped import damped_frequencies
from linmstmm.fe import damped_roots
from linmstmm.model import load_model
from linmstmm.solve import natural_frequencies

ROOT = Path(__file__).resolve().parents[1]


def hand_roots(damping) -> np.ndarray:
    """(2,) roots s with Im s > 0 of the chain's hand-written quadratic eigenproblem, ascending."""
    zero, identity = np.zeros((2, 2)), np.eye(2)
    s = scipy.linalg.eigvals(np.block([[zero, identity], [-K_HAND, -damping]]),
                             np.block([[identity, zero], [zero, M_HAND]]))
    s = s[s.imag > 0]
    return s[np.argsort(s.imag)]


@pytest.mark.parametrize("rayleigh", [None, (0.3, 2e-4)])
def test_dashpot_chain_roots_match_the_quadratic_eigenproblem(rayleigh):
    model = dashpot_chain(rayleigh)
    alpha, beta = (0.0, 0.0) if rayleigh is None else rayleigh
    want = np.repeat(hand_roots(C_HAND + alpha * M_HAND + beta * K_HAND), 3)  # x, y, z alike
    result = damped_frequencies(model, count=6)
    assert relative(result.roots, want) < 1e-12
    assert relative(damped_roots(model, 1)[:6], want) < 1e-12
    assert result.damping_ratio[3] > 0.15  # the dashpot works on the masses' relative motion
    np.testing.assert_allclose(result.damped_frequencies_hz, want.imag / (2 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(result.damping_ratio, -want.real / np.abs(want), rtol=1e-10)


def test_rayleigh_damping_alone_gives_the_modal_ratios():
    model = dataclasses.replace(load_model(ROOT / "models/cantilever_tip_mass.toml"), damping=(0.8, 3e-4))
    undamped = 2 * np.pi * natural_frequencies(model, count=4).frequencies_hz
    result = damped_frequencies(model, count=4)
    np.testing.assert_allclose(result.frequencies_hz * 2 * np.pi, undamped, rtol=1e-11)
    np.testing.assert_allclose(result.damping_ratio, 0.8 / (2 * undamped) + 3e-4 * undamped / 2, rtol=1e-9)


def test_launcher_with_damped_jacks_agrees_with_fe():
    """FE errors of the lowest six roots fall with the mesh (the tube's two beams)."""
    model = load_model(ROOT / "models/mlrs/mlrs.toml")
    damped = with_dashpots(model, {f"tyre{i}": [2e4, 2e4, 3e4, 0.0, 0.0, 0.0] for i in (1, 2, 5, 6)})
    result = damped_frequencies(damped, count=6)
    assert np.all(result.damping_ratio > 5e-3)
    errors = []
    for n in (2, 4):
        fe = damped_roots(damped, n)
        errors.append(max(np.abs(fe - s).min() / abs(s) for s in result.roots))
    assert errors[1] < errors[0] / 4 and errors[1] < 1e-6, errors


def test_a_dashpot_that_splits_a_double_root_gives_both_roots(tmp_path):
    """The tip-mass cantilever's bending roots are double (Iy = Iz); a tip dashpot of
    30 N s/m along y and 60 along z splits each into two roots of different damping
    (the search from the double root found neither before). FE route on 16 and 32
    elements per beam: its distance to them falls as h⁴ (2.7e-5, then 1.7e-6)."""
    model = cantilever_with_tip_dashpot(tmp_path)
    result = damped_frequencies(model, count=6)
    assert len(set(np.round(result.damping_ratio, 6))) == 6
    errors = [max(np.abs(damped_roots(model, n) - s).min() / abs(s) for s in result.roots) for n in (16, 32)]
    assert errors[1] < errors[0] / 8 and errors[1] < 1e-5, errors


def test_freqs_damped_command(capsys):
    chain = ROOT / "models/dashpot_chain.toml"
    status, out, _ = command(capsys, "freqs", chain, "--damped", "--count", "6", "--json")
    assert status == 0
    data = json.loads(out)
    want = np.repeat(hand_roots(C_HAND), 3)
    got = np.array([complex(*s) for s in data["roots"]])
    assert relative(got, want) < 1e-12 and data["method"] == "mstmm-damped"
    np.testing.assert_allclose(data["damping_ratio"], -want.real / np.abs(want), rtol=1e-10)
    assert len(data["undamped_frequencies_hz"]) == 6 and data["rigid_body_modes"] == 0
    np.testing.assert_allclose(data["damped_frequencies_hz"], want.imag / (2 * np.pi), rtol=1e-12)
    np.testing.assert_allclose(data["frequencies_hz"], np.abs(want) / (2 * np.pi), rtol=1e-12)
    status, out, _ = command(capsys, "freqs", chain, "--damped", "--count", "2")
    assert status == 0 and "damping ratio" in out and out.count("2.397144683") == 3  # the whole eigenspace
    status, out, err = command(capsys, "freqs", chain, "--damped", "--digits", "20")
    assert status == 2 and out == "" and "key '--digits'" in err


def test_freqs_damped_csv_and_output_hold_the_json(capsys, tmp_path):
    chain = ROOT / "models/dashpot_chain.toml"
    status, table, err = command(capsys, "freqs", chain, "--damped", "--count", "3", "--csv", tmp_path / "d.csv",
                                 "--output", tmp_path / "d.json")
    assert status == 0 and "wrote" in table and "damping ratio" in table, err
    data = json.loads((tmp_path / "d.json").read_text())
    header, *rows = (tmp_path / "d.csv").read_text().splitlines()
    assert header == ("mode,damped frequency [Hz],damping ratio,frequency |s|/2pi [Hz],s real [1/s],"
                      "s imag [1/s]")
    rows = np.array([row.split(",") for row in rows], dtype=float)
    assert rows[:, 0].tolist() == [1, 2, 3] and rows[:, 1].tolist() == data["damped_frequencies_hz"]
    assert rows[:, 2].tolist() == data["damping_ratio"] and rows[:, 3].tolist() == data["frequencies_hz"]
    assert rows[:, 4:].tolist() == data["roots"]


def test_undamped_model_has_real_roots():
    result = damped_frequencies(spring_mass_chain(), count=6)
    assert np.abs(result.damping_ratio).max() < 1e-12


@pytest.mark.parametrize("kind, seed", [("floating_tree", 2), ("ring", 2), ("loops", 2), ("tree", 0)])
def test_random_models_with_dashpots_and_rayleigh_agree_with_fe(kind, seed):
    """Free-floating, ring, loops and tree models with beams: FE errors fall about 16
    times per mesh doubling (Hermite bending) towards the transfer-matrix roots."""
    model = random_model(kind, seed)
    model = dataclasses.replace(with_dashpots(model, {s.name: 1e-4 * np.minimum(s.k, 1e12) for s in model.springs}),
                                damping=(0.5, 1e-5))
    result = damped_frequencies(model, count=5)
    assert np.all(result.damping_ratio > 1e-3)
    errors = [max(np.abs(damped_roots(model, n) - s).min() / abs(s) for s in result.roots) for n in (4, 8)]
    assert errors[1] < errors[0] / 8 and errors[1] < 1e-4, errors
