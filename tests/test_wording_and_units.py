"""What results say: counts in the number that fits, the units of a rotation
mode's modal mass and stiffness, and one rule for a model that falls apart.

References in closed form: a 2 kg body (inertia 0.5 kg m² about each axis) on
a spring of [800, 1800, 3200] N/m and [50, 200, 450] N m/rad: six modes, each
one direction, ω² = k / m or k_r / I; scaled to a largest translation of
1 m or a largest rotation of 1 rad, M_k is m or I and K_k is k or k_r.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from builders import fixed, make_beam, make_rigid, make_spring

import linmstmm as lm
from linmstmm.model import ModelError
from linmstmm.wording import counted

ROOT = Path(__file__).resolve().parents[1]
STIFFNESS = [800.0, 1800.0, 3200.0, 50.0, 200.0, 450.0]


def body_on_a_spring(k=STIFFNESS) -> lm.Model:
    points = {"ground": np.zeros(3), "a": np.zeros(3)}
    return lm.Model("body on a spring", points, rigids=(make_rigid("m", ["a"], 2.0, np.zeros(3), [0.5] * 3),),
                    springs=(make_spring("k", "ground", "a", k),), boundary={"ground": fixed()})


def test_counted_takes_the_number_that_fits():
    assert counted(1, "elastic mode") == "1 elastic mode"
    assert counted(0, "elastic mode") == "0 elastic modes"
    assert counted(2, "frequency exists", "frequencies exist") == "2 frequencies exist"


def test_one_elastic_frequency_is_one_frequency_in_the_notes():
    model = body_on_a_spring([800.0] + [np.inf] * 5)  # x alone moves: ω = 20 rad/s
    mstmm, fe = lm.natural_frequencies(model, count=3), lm.fe_frequencies(model, count=3)
    np.testing.assert_allclose([mstmm.frequencies_hz, fe.frequencies_hz], [[20 / (2 * np.pi)]] * 2, rtol=1e-12)
    assert mstmm.note.startswith("only 1 elastic natural frequency exists below")
    assert fe.note.startswith("only 1 elastic natural frequency exists (directions with mass less the "
                              "0 rigid-body modes)")


def test_a_rotation_mode_scaled_to_one_radian_has_an_inertia_for_modal_mass():
    modes = lm.mode_shapes(body_on_a_spring(), count=6, normalization="max")
    inertia = np.array([2.0, 2.0, 2.0, 0.5, 0.5, 0.5])
    omega2 = np.array(STIFFNESS) / inertia
    order = np.argsort(omega2, kind="stable")
    np.testing.assert_allclose(modes.omega ** 2, omega2[order], rtol=1e-12)
    rotation = order >= 3
    # a translation and a rotation share each frequency, in either order: compare as sets
    got = sorted(zip(np.round(modes.omega ** 2, 6), np.round(modes.modal_mass, 9), np.round(modes.modal_stiffness, 6),
                     modes.modal_mass_units, modes.modal_stiffness_units))
    want = sorted(zip(np.round(omega2[order], 6), inertia[order], np.array(STIFFNESS)[order],
                      np.where(rotation, "kg m^2", "kg"), np.where(rotation, "N m/rad", "N/m")))
    assert got == want
    data = modes.to_dict()
    assert data["modal_mass_units"] == modes.modal_mass_units
    assert lm.mode_shapes(body_on_a_spring(), count=6).modal_mass_units == ["kg"] * 6  # mass-normalised: 1 kg


def test_the_modes_table_gives_each_modal_mass_its_unit(tmp_path):
    model = tmp_path / "body.toml"
    model.write_text('name = "body on a spring"\n[points]\ng = [0.0, 0.0, 0.0]\na = [0.0, 0.0, 0.0]\n'
                     '[[rigid]]\nname = "m"\nports = ["a"]\nmass = 2.0\ncom = [0.0, 0.0, 0.0]\n'
                     'inertia = [0.5, 0.5, 0.5]\n[[spring]]\nname = "k"\nends = ["g", "a"]\n'
                     f'k = {STIFFNESS}\n[boundary]\ng = "fixed"\n')
    run = subprocess.run([sys.executable, "-m", "linmstmm", "modes", str(model), "--count", "6",
                          "--normalization", "max"], capture_output=True, text=True, cwd=ROOT, check=True)
    first = next(line for line in run.stdout.splitlines() if line.split()[:1] == ["1"])
    assert first.split()[2:] == ["0.5", "kg", "m^2", "50", "N", "m/rad"]


def two_separate_cantilevers() -> lm.Model:
    points = {"r1": np.zeros(3), "t1": np.array([2.0, 0, 0]), "r2": np.array([0, 1.0, 0]),
              "t2": np.array([2.0, 1.0, 0])}
    return lm.Model("two cantilevers", points,
                    beams=(make_beam("b1", "r1", "t1", points), make_beam("b2", "r2", "t2", points)),
                    boundary={"r1": fixed(), "r2": fixed()})


def test_a_model_that_falls_apart_is_refused_naming_an_element_apart():
    with pytest.raises(ModelError) as error:
        two_separate_cantilevers()
    assert error.value.element == "beam 'b2'" and error.value.key == "ends"
    assert "not connected to beam 'b1'" in error.value.message


def test_two_bodies_at_one_place_without_an_element_between_them_are_apart():
    points = {"g": np.zeros(3), "a": np.zeros(3), "b": np.zeros(3)}
    with pytest.raises(ModelError) as error:
        lm.Model("apart", points, rigids=(make_rigid("m1", ["a"], 1.0, np.zeros(3), [0.1] * 3),
                                          make_rigid("m2", ["b"], 1.0, np.zeros(3), [0.1] * 3)),
                 springs=(make_spring("k", "g", "a", STIFFNESS),), boundary={"g": fixed()})
    assert error.value.element == "rigid 'm2'" and error.value.key == "ports"


@pytest.mark.parametrize("command", ["freqs", "fe", "modes", "check"])
def test_every_command_refuses_a_model_that_falls_apart_alike(tmp_path, command):
    model = tmp_path / "apart.toml"
    beam = 'E = 2.1e11\nG = 8.1e10\nrho = 7850.0\nA = 1.0e-3\nIy = 2.0e-7\nIz = 2.0e-7\nJ = 4.0e-7\n'
    model.write_text('name = "apart"\n[points]\nr1 = [0.0, 0.0, 0.0]\nt1 = [2.0, 0.0, 0.0]\n'
                     'r2 = [0.0, 1.0, 0.0]\nt2 = [2.0, 1.0, 0.0]\n'
                     f'[[beam]]\nname = "b1"\nends = ["r1", "t1"]\n{beam}'
                     f'[[beam]]\nname = "b2"\nends = ["r2", "t2"]\n{beam}'
                     '[boundary]\nr1 = "fixed"\nr2 = "fixed"\n')
    run = subprocess.run([sys.executable, "-m", "linmstmm", command, str(model)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 2 and run.stdout == ""
    assert run.stderr.strip() == (f"linmstmm: error: {model}: beam 'b2': key 'ends': not connected to beam 'b1': "
                                  f"no chain of elements joins its points r2, t2 to it (1 of 2 elements apart); "
                                  f"a model is one connected structure (a boundary condition joins nothing): "
                                  f"give each part its own model")
