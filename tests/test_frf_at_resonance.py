"""The undamped receptance at a natural frequency: unbounded, so said, never NaN.

Reference: a 2 kg body on an 800 N/m spring along x (rigid otherwise),
H(Ω) = 1 / (k − m Ω² + i c Ω) with c = 2 ζ √(k m); ω = 20 rad/s.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from builders import fixed, make_rigid, make_spring

import linmstmm as lm
from linmstmm.model import ModelError
from linmstmm.response import ResonanceError, undamped_resonances
from linmstmm.studies import frf_study

ROOT = Path(__file__).resolve().parents[1]
K, M = 800.0, 2.0
NATURAL_HZ = 20.0 / (2 * np.pi)
X_LOAD = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]


def body_on_an_x_spring() -> lm.Model:
    points = {"ground": np.zeros(3), "a": np.zeros(3)}
    return lm.Model("body on an x spring", points,
                    rigids=(make_rigid("m", ["a"], M, np.zeros(3), [0.1, 0.1, 0.1]),),
                    springs=(make_spring("k", "ground", "a", [K] + [np.inf] * 5),),
                    boundary={"ground": fixed()})


def exact(hz, zeta=0.0):
    """(n,) the x receptance at a, m/N."""
    omega = 2 * np.pi * np.asarray(hz)
    return 1 / (K - M * omega ** 2 + 2j * zeta * np.sqrt(K * M) * omega)


@pytest.mark.parametrize("offset", [0.0, 1e-12, -5e-10])
def test_frf_refuses_an_excitation_at_an_undamped_natural_frequency(offset):
    modes = lm.mode_shapes(body_on_an_x_spring(), count=1)
    hz = NATURAL_HZ * (1 + offset)
    with pytest.raises(ResonanceError, match="unbounded at 3.18309886"):
        lm.frf(modes, "a", X_LOAD, [1.0, hz], ["a"])


def test_frf_near_but_off_a_natural_frequency_and_damped_at_it_is_finite_and_exact():
    modes = lm.mode_shapes(body_on_an_x_spring(), count=1)
    near = NATURAL_HZ * np.array([1 - 1e-6, 1 + 1e-6])
    got = lm.frf(modes, "a", X_LOAD, near, ["a"]).receptance[:, 0, 0]
    np.testing.assert_allclose(got, exact(near), rtol=1e-6)  # ω itself is certified to 1e-9
    damped = lm.frf(modes, "a", X_LOAD, [NATURAL_HZ], ["a"], damping_ratio=0.02).receptance[:, 0, 0]
    np.testing.assert_allclose(damped, exact([NATURAL_HZ], 0.02), rtol=1e-9)


def test_undamped_resonances_ignores_damped_modes():
    omega, hz = np.array([0.0, 20.0, 30.0]), np.array([0.0, 20.0, 30.0]) / (2 * np.pi)
    assert undamped_resonances(omega, np.array([0.0, 0.0, 0.0]), hz).tolist() == [True, True, True]
    assert undamped_resonances(omega, np.array([0.0, 0.8, 0.0]), hz).tolist() == [True, False, True]
    assert undamped_resonances(omega, np.array([0.1, 0.8, 1.2]), hz).tolist() == [False, False, False]


def test_a_sweep_through_a_natural_frequency_leaves_it_out_and_says_so():
    result, summary = frf_study(body_on_an_x_spring(), "a", "x", NATURAL_HZ, frequencies=4)
    np.testing.assert_allclose(result.excitation_hz, NATURAL_HZ * np.array([0.25, 0.5, 0.75]), rtol=1e-15)
    np.testing.assert_allclose(result.receptance[:, 0, 0], exact(result.excitation_hz), rtol=1e-9)
    assert summary["unbounded_hz"] == [NATURAL_HZ]
    assert "leaves out 3.183098862 Hz" in summary["note"]
    with pytest.raises(ModelError) as error:
        frf_study(body_on_an_x_spring(), "a", "x", NATURAL_HZ, frequencies=1)
    assert error.value.key == "fmax"


def test_the_command_writes_strict_json_and_a_note(tmp_path):
    model = tmp_path / "sdof.toml"
    model.write_text('name = "sdof x"\n[points]\ng = [0.0, 0.0, 0.0]\na = [0.0, 0.0, 0.0]\n'
                     '[[rigid]]\nname = "m"\nports = ["a"]\nmass = 2.0\ncom = [0.0, 0.0, 0.0]\n'
                     'inertia = [0.1, 0.1, 0.1]\n[[spring]]\nname = "k"\nends = ["g", "a"]\n'
                     'k = [800.0, inf, inf, inf, inf, inf]\n[boundary]\ng = "fixed"\n')
    command = [sys.executable, "-m", "linmstmm", "frf", str(model), "--point", "a",
               "--direction", "x", "--fmax", repr(NATURAL_HZ), "--frequencies", "4"]

    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")

    run = subprocess.run(command + ["--json"], capture_output=True, text=True, cwd=ROOT, check=True)
    data = json.loads(run.stdout, parse_constant=refuse)
    assert data["unbounded_hz"] == [NATURAL_HZ] and len(data["excitation_hz"]) == 3 and run.stderr == ""
    table = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, check=True).stdout
    assert "note: the sweep leaves out 3.183098862 Hz" in table
