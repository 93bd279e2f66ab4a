"""The direct transfer-matrix FRF (linmstmm.forced) against independent solutions.

* the two-mass chain with a dashpot between the masses: its M, C, K written by
  hand here and (K + iΩC − Ω²M) x = f solved directly, and the FE route's
  complex solve (both exact for springs and bodies, so agreement to rounding);
* without dashpots, the modal sum over all six modes of the chain (exact for
  Rayleigh damping, which the direct route maps onto a complex frequency);
* beams: the FE route's complex solve on refined meshes, whose discretisation
  error must shrink towards the transfer-matrix result;
* loads at every kind of port (tips, roots, junctions, loop cuts, a closed
  ring) on random models, and the launcher with damped jacks.
"""
from __future__ import annotations

import dataclasses
import json
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
from builders import fixed, make_beam, make_rigid, single_beam_model, spring_mass_chain
from random_models import random_model

from linmstmm import cli
from linmstmm.fe import harmonic_receptance
from linmstmm.forced import direct_frf, has_dashpots
from linmstmm.model import Model, Spring, load_model
from linmstmm.modes import mode_shapes
from linmstmm.response import frf

ROOT = Path(__file__).resolve().parents[1]
K_CHAIN, M_CHAIN, C_MIDDLE = 1000.0, 2.0, 20.0
RAYLEIGH = (0.3, 2e-4)
M_HAND = np.diag([3 * M_CHAIN, M_CHAIN])
K_HAND = K_CHAIN * np.array([[2.0, -1.0], [-1.0, 2.0]])
C_HAND = C_MIDDLE * np.array([[1.0, -1.0], [-1.0, 1.0]])
FORCE = np.array([1.0, -0.5, 0.25])


def with_dashpots(model: Model, c: dict) -> Model:
    """``model`` with the dashpots ``c`` (spring name -> (6,)) added to its springs."""
    springs = tuple(dataclasses.replace(s, c=np.asarray(c[s.name], float)) if s.name in c else s
                    for s in model.springs)
    return dataclasses.replace(model, springs=springs)


def dashpot_chain(damping=None) -> Model:
    """fixed–k–3m–k(+20 N s/m)–m–k–fixed along x, every translation the same 2-DOF chain."""
    return with_dashpots(spring_mass_chain(K_CHAIN, M_CHAIN, damping),
                         {"k2": [C_MIDDLE] * 3 + [0.0] * 3})


def relative(got, want) -> float:
    return float(np.abs(got - want).max() / np.abs(want).max())


@pytest.mark.parametrize("damping", [None, RAYLEIGH])
@pytest.mark.parametrize("point, mass", [("b1", 0), ("a2", 1), ("b2", 1)])
def test_dashpot_chain_matches_hand_written_solve_and_fe(point, mass, damping):
    model = dashpot_chain()
    frequencies = np.linspace(0.5, 12.0, 60)
    got = direct_frf(model, point, np.r_[FORCE, 0, 0, 0], frequencies, ["a1", "b2"], damping=damping).receptance
    alpha, beta = (0.0, 0.0) if damping is None else damping
    load = np.eye(2)[:, mass]
    for H, f in zip(got, frequencies):
        W = 2 * np.pi * f
        viscous = C_HAND + alpha * M_HAND + beta * K_HAND
        want = np.linalg.solve(K_HAND + 1j * W * viscous - W**2 * M_HAND, load)[:, None] * FORCE  # (2, 3)
        assert relative(H[:, :3], want) < 1e-12
        assert np.abs(H[:, 3:]).max() < 1e-12 * np.abs(want).max()
    fe = harmonic_receptance(model, point, np.r_[FORCE, 0, 0, 0], frequencies, ["a1", "b2"], damping=damping)
    assert relative(got, fe) < 1e-12
    undamped = direct_frf(spring_mass_chain(K_CHAIN, M_CHAIN), point, np.r_[FORCE, 0, 0, 0], frequencies,
                          ["a1", "b2"], damping=damping).receptance
    assert relative(got, undamped) > 0.3  # the dashpot acts


def test_without_dashpots_the_direct_route_is_the_complete_modal_sum():
    model = spring_mass_chain(K_CHAIN, M_CHAIN, RAYLEIGH)
    assert not has_dashpots(model) and has_dashpots(dashpot_chain())
    frequencies = np.linspace(0.5, 12.0, 60)
    vector = np.r_[FORCE, 0.0, 0.0, 0.0]
    modal = frf(mode_shapes(model, count=6), "b1", vector, frequencies, ["a1", "b2"], RAYLEIGH).receptance
    got = direct_frf(model, "b1", vector, frequencies, ["a1", "b2"], damping=RAYLEIGH).receptance
    assert relative(got, modal) < 1e-12


def pad_cantilever() -> Model:
    """A 2 m steel cantilever with a 5 kg tip mass on a spring and dashpot pad to ground."""
    points = {"root": np.zeros(3), "tip": np.array([2.0, 0.0, 0.0]), "ground": np.array([2.0, 0.0, 0.0])}
    pad = Spring("pad", ("tip", "ground"), np.r_[2e4, 2e4, 2e4, 1e3, 1e3, 1e3], np.eye(3),
                 np.r_[80.0, 80.0, 80.0, 2.0, 2.0, 2.0])
    return Model("cantilever on a damped pad", points, beams=(make_beam("arm", "root", "tip", points),),
                 rigids=(make_rigid("payload", ["tip"], 5.0, [2.0, 0.0, 0.0]),), springs=(pad,),
                 boundary={"root": fixed(), "ground": fixed()})


def test_beam_with_dashpot_to_ground_converges_to_the_direct_route():
    """Modes at 10.2, 51.3, 153 Hz (bending, each in two planes): the sweep spans them.
    FE errors shrink with every mesh doubling: 0.1 % on 4 elements, 5e-6 on 32 (h⁴ of the
    Hermite bending first, then h² of the linear axial and torsion elements)."""
    model = pad_cantilever()
    frequencies = np.array([2.0, 7.0, 15.0, 40.0, 90.0, 200.0])
    vector = np.r_[100.0, 0.0, -1.0, 0.3, 0.2, 0.1]
    got = direct_frf(model, "tip", vector, frequencies, ["tip"]).receptance
    errors = [relative(got, harmonic_receptance(model, "tip", vector, frequencies, ["tip"], n))
              for n in (4, 8, 16, 32)]
    assert all(finer < coarser / 3.5 for coarser, finer in pairwise(errors)), errors
    assert errors[-1] < 1e-5


#: Random models with beams where the FE error shrinks cleanly over 4-8-16 elements
#: (on finer meshes the assembled K's rounding takes over); between them loads at
#: tips, junctions, loop cuts and a ring's closing point.
RANDOM_CASES = [("tree", 0), ("floating_tree", 2), ("loops", 2), ("floating_loops", 0), ("ring", 2)]


@pytest.mark.parametrize("kind, seed", RANDOM_CASES)
def test_random_models_with_dashpots_agree_with_fe(kind, seed):
    model = random_model(kind, seed)
    model = with_dashpots(model, {s.name: 1e-4 * np.minimum(s.k, 1e12) for s in model.springs})
    free = [p for p in model.points if p not in model.boundary]
    first = min(mode_shapes(model, count=1, rigid_body=False).frequencies_hz)
    frequencies = np.array([0.37, 0.93, 1.6, 2.3]) * first
    rng = np.random.default_rng(seed)
    for point in free[::max(1, len(free) // 4)]:
        vector = rng.standard_normal(6)
        fe = [harmonic_receptance(model, point, vector, frequencies, free, n, damping=(0.1, 1e-5)) for n in (4, 8, 16)]
        for orthonormalise in (None, True, False):  # the rule's choice, and both carries
            got = direct_frf(model, point, vector, frequencies, free, damping=(0.1, 1e-5),
                             orthonormalise=orthonormalise).receptance
            errors = [relative(got, solution) for solution in fe]
            assert errors[1] < errors[0] / 8 and errors[2] < errors[1] / 4 and errors[2] < 2e-5, (point, errors)


def test_loaded_root_and_other_roots_give_the_same_receptance():
    """The load at the root itself (its jump enters the main equation) and at a tip,
    with the transfer tree rooted at each boundary end in turn."""
    model = pad_cantilever()
    frequencies = np.array([3.0, 30.0])
    vector = np.r_[1.0, 2.0, 3.0, 0.1, 0.2, 0.3]
    free_tip = dataclasses.replace(model, boundary={"root": fixed()})  # the pad's far end is free
    for load in ("tip", "ground"):
        results = [direct_frf(free_tip, load, vector, frequencies, ["tip", "ground"], root=root).receptance
                   for root in ("root", "ground")]
        assert relative(results[1], results[0]) < 1e-12


def test_launcher_with_damped_jacks_agrees_with_fe():
    """The MLRS-style launcher with dashpots in its four tyre-and-jack hinges: FE errors
    fall about 16 times per mesh doubling (Hermite bending of the tube's two beams)."""
    model = load_model(ROOT / "models/mlrs/mlrs.toml")
    jacks = {f"tyre{i}": [2e4, 2e4, 3e4, 0.0, 0.0, 0.0] for i in (1, 2, 5, 6)}
    damped = with_dashpots(model, jacks)
    frequencies = np.array([1.0, 2.4, 4.0, 9.0, 20.0])
    vector = np.eye(6)[2]
    got = direct_frf(damped, "tube_rear", vector, frequencies, ["tube_rear"]).receptance
    errors = [relative(got, harmonic_receptance(damped, "tube_rear", vector, frequencies, ["tube_rear"], n))
              for n in (4, 8, 16)]
    assert errors[1] < errors[0] / 8 and errors[2] < errors[1] / 8 and errors[2] < 1e-4, errors
    undamped = direct_frf(model, "tube_rear", vector, frequencies, ["tube_rear"]).receptance
    assert relative(got, undamped) > 1e-2


# --- the command line ------------------------------------------------------------

DASHPOT_CHAIN_FILE = ROOT / "models/dashpot_chain.toml"


def command(capsys, *argv):
    status = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


def test_frf_command_takes_the_direct_route_for_dashpots(capsys):
    """The bundled chain with a dashpot is :func:`dashpot_chain`; its JSON has the
    modal route's keys, and the receptance is the hand-written direct solve."""
    status, out, _ = command(capsys, "frf", DASHPOT_CHAIN_FILE, "--point", "b2", "--direction", "y",
                             "--fmax", "10", "--frequencies", "20", "--response-points", "b1", "b2", "--json")
    assert status == 0
    data = json.loads(out)
    modal = json.loads(command(capsys, "frf", ROOT / "models/spring_mass_chain.toml", "--point", "b2",
                               "--direction", "y", "--fmax", "10", "--frequencies", "20", "--json")[1])
    assert set(data) == set(modal) and (data["route"], modal["route"]) == ("direct", "modal")
    assert data["modes_in_sum"] == 0 and data["rigid_body_modes"] == 0
    np.testing.assert_allclose(data["frequencies_hz"], modal["frequencies_hz"], rtol=1e-12)  # the undamped chain's
    got = np.array([[np.array(data["receptance"][p]["real"]) + 1j * np.array(data["receptance"][p]["imag"])]
                    for p in ("b1", "b2")])[:, 0]  # (2, n_f, 6)
    for f, H in zip(data["excitation_hz"], np.moveaxis(got, 1, 0)):
        W = 2 * np.pi * f
        want = np.linalg.solve(K_HAND + 1j * W * C_HAND - W**2 * M_HAND, np.eye(2)[:, 1])
        assert relative(H[:, 1], want) < 1e-12 and np.abs(H[:, [0, 2, 3, 4, 5]]).max() < 1e-12 * np.abs(want).max()
    status, out, _ = command(capsys, "frf", DASHPOT_CHAIN_FILE, "--point", "b2", "--direction", "y",
                             "--fmax", "10", "--frequencies", "20")
    assert status == 0 and "direct transfer-matrix solve" in out and "no Rayleigh damping" in out


@pytest.mark.parametrize("option, what", [(("--zeta", "0.02"), "modal damping ratios"),
                                          (("--modes", "3"), "a number of modes in the sum")])
def test_modal_options_with_dashpots_exit_2(capsys, option, what):
    status, out, err = command(capsys, "frf", DASHPOT_CHAIN_FILE, "--point", "b2", "--direction", "y",
                               "--fmax", "10", *option)
    assert status == 2 and out == ""
    assert err.strip() == (f"linmstmm: error: {DASHPOT_CHAIN_FILE}: key '{option[0]}': the model's spring "
                           f"dashpots 'c' take the direct route, which sums no modes: {what} belong to "
                           f"the modal route; give [damping] for more damping")


@pytest.mark.parametrize("parameter, value", [("modes", 3), ("damping_ratio", [0.02])])
def test_frf_study_names_the_parameter_not_the_option(parameter, value):
    """The library names its parameter; the command line turns it into the option (above)."""
    from linmstmm.model import ModelError
    from linmstmm.studies import frf_study

    with pytest.raises(ModelError) as error:
        frf_study(load_model(DASHPOT_CHAIN_FILE), "b2", "y", 10.0, frequencies=4, **{parameter: value})
    assert error.value.key == parameter


def test_frf_study_takes_the_direct_route_for_dashpots():
    """frf_study's summary on the direct route: the undamped frequencies up to fmax, no modes."""
    from linmstmm.studies import frf_study, frf_text

    model = load_model(DASHPOT_CHAIN_FILE)
    result, summary = frf_study(model, "b2", "x", 4.0, frequencies=8, response_points=["b1", "b2"])
    assert summary["route"] == "direct" and summary["modes_in_sum"] == 0
    assert summary["frequencies_hz"] == pytest.approx([2.391077861106958] * 3, rel=1e-12)
    want = direct_frf(model, "b2", np.eye(6)[0], result.excitation_hz, ["b1", "b2"]).receptance
    assert np.array_equal(result.receptance, want)
    assert "natural frequencies (undamped) [Hz]: 2.39108, 2.39108, 2.39108" in frf_text(result, summary)


def test_cantilever_tip_receptance_matches_closed_form_far_above_the_first_modes():
    """Euler-Bernoulli cantilever, tip force along z: H = (sin x cosh x − cos x sinh x) /
    (EI β³ (1 + cos x cosh x)), x = βL, from βL = 1 to 185 (the growing solutions e^{βL}
    reach 1e80; the orthonormalised carry keeps every digit, and takes over from the plain
    one above βL = 4)."""
    model = single_beam_model(left=fixed(), length=2.0)
    beam = model.beams[0]
    frequencies = np.array([3.0, 30.0, 300.0, 1000.0, 8000.0, 32000.0, 100000.0])
    beta = (beam.rho * beam.A * (2 * np.pi * frequencies) ** 2 / (beam.E * beam.Iy)) ** 0.25
    x = beta * beam.length
    want = ((np.sin(x) * np.cosh(x) - np.cos(x) * np.sinh(x))
            / (beam.E * beam.Iy * beta**3 * (1 + np.cos(x) * np.cosh(x))))
    got = direct_frf(model, "b", np.eye(6)[2], frequencies, ["b"]).receptance
    np.testing.assert_allclose(got[:, 0, 2], want, rtol=1e-12)
    assert np.all(np.abs(got[:, 0, [0, 1, 3, 5]]).max(axis=1) < 1e-12 * np.abs(want))


# --- joints ----------------------------------------------------------------------

def damped_hinged_chain(ct=4.0, released=False):
    """tests/test_joints.py's two hinged rods, a rotary dashpot ct (N m s/rad) beside each
    torsion spring (its kept direction rz); ``released``: one on a pin's released rz instead."""
    from test_joints import hinged_chain

    model = hinged_chain()
    name, c = ("pin", [0.0] * 5 + [ct]) if released else ("torsion", [0.0] * 5 + [ct])
    return with_dashpots(model, {f"{name}{i}": c for i in (1, 2)})


def test_joints_with_rotary_dashpots_agree_with_fe_and_the_quadratic_eigenproblem():
    """Rods and springs only: the FE route is exact, so the direct FRF and the damped
    roots agree with it to rounding, the joints' released jumps carried alongside."""
    from linmstmm.damped import damped_frequencies
    from linmstmm.fe import damped_roots

    model = damped_hinged_chain()
    frequencies = np.array([0.5, 1.3, 2.9, 7.0, 15.0])
    vector = np.eye(6)[1]  # y at the free end
    got = direct_frf(model, "b2", vector, frequencies, ["b1", "b2"], damping=(0.2, 1e-4)).receptance
    want = harmonic_receptance(model, "b2", vector, frequencies, ["b1", "b2"], damping=(0.2, 1e-4))
    assert relative(got, want) < 1e-10
    roots = damped_frequencies(model, count=2).roots
    assert relative(roots, damped_roots(model, 1)[:2]) < 1e-10 and np.all(roots.real < 0)


def test_a_dashpot_in_a_released_direction_is_refused():
    from linmstmm.damped import damped_frequencies
    from linmstmm.model import ModelError

    model = damped_hinged_chain(released=True)
    for solve in (lambda: direct_frf(model, "b2", np.eye(6)[1], [1.0]), lambda: damped_frequencies(model, 2)):
        with pytest.raises(ModelError, match="released direction") as error:
            solve()
        assert error.value.key == "c" and error.value.element == "spring 'pin1'"
