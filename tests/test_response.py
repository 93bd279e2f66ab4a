"""Modal response and FRF (linmstmm.response) against closed forms and direct solves.

The single-DOF model is a mass on a spring that is rigid (``inf``) in every
direction but x, so it has exactly one mode, ω = √(k/m); its responses are
the textbook Duhamel integrals. The two-mass chain's M and K are written by
hand here, and its FRF and impulse response are solved directly.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg
from builders import fixed, make_rigid, make_spring, spring_mass_chain

from linmstmm import cli
from linmstmm.model import Model, ModelError
from linmstmm.modes import mode_shapes
from linmstmm.response import (DampingRatioError, PointLoad, frf, half_sine, harmonic, impulse, load_loads,
                               modal_response, respond, step, table, unit_response)

K_SDOF, M_SDOF, F = 4.0e4, 2.5, 30.0
OMEGA = np.sqrt(K_SDOF / M_SDOF)
TIMES = np.linspace(0.0, 1.5, 3001)


def sdof(damping=None):
    points = {"g": np.zeros(3), "p": np.zeros(3)}
    return Model("sdof", points, rigids=(make_rigid("mass", ["p"], M_SDOF, [0.0, 0.0, 0.0]),),
                 springs=(make_spring("k", "g", "p", [K_SDOF] + [np.inf] * 5),),
                 boundary={"g": fixed()}, damping=damping)


def sdof_response(function, damping=None, damping_ratio=None):
    model = sdof(damping)
    modes = mode_shapes(model, count=1)
    assert modes.omega == pytest.approx([OMEGA], rel=1e-13)
    load = PointLoad("p", np.array([F, 0.0, 0.0]), np.zeros(3), function)
    result = modal_response(modes, [load], TIMES, ["p"], model.damping, damping_ratio=damping_ratio)
    return result.displacement[:, 0, 0], result.velocity[:, 0, 0], result.acceleration[:, 0, 0]


def assert_history(got, want):
    assert np.abs(got - want).max() < 1e-10 * np.abs(want).max()


@pytest.mark.parametrize("by", ["rayleigh", "ratio"])
def test_step_with_damping(by):
    zeta = 0.03
    if by == "rayleigh":
        x, v, a = sdof_response(step(0.1), damping=(2 * zeta * OMEGA, 0.0))
    else:
        x, v, a = sdof_response(step(0.1), damping_ratio=zeta)
    tau = np.maximum(TIMES - 0.1, 0.0)
    wd = OMEGA * np.sqrt(1 - zeta**2)
    decay = np.exp(-zeta * OMEGA * tau)
    want = F / K_SDOF * (1 - decay * (np.cos(wd * tau) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * tau)))
    assert_history(x, np.where(TIMES >= 0.1, want, 0.0))
    assert_history(v, np.where(TIMES >= 0.1, F / (M_SDOF * wd) * decay * np.sin(wd * tau), 0.0))


def test_impulse_with_stiffness_proportional_damping():
    beta = 2e-4
    zeta = beta * OMEGA / 2
    x, v, a = sdof_response(impulse(0.05), damping=(0.0, beta))
    tau = np.maximum(TIMES - 0.05, 0.0)
    wd = OMEGA * np.sqrt(1 - zeta**2)
    want = F / (M_SDOF * wd) * np.exp(-zeta * OMEGA * tau) * np.sin(wd * tau)
    assert_history(x, np.where(TIMES >= 0.05, want, 0.0))
    assert_history(a, np.where(TIMES >= 0.05, -2 * zeta * OMEGA * v - OMEGA**2 * want, 0.0))


def _undamped_sine(rate, tau):
    """Response to F sin(rate τ) from rest, undamped."""
    r = rate / OMEGA
    return F / K_SDOF * (np.sin(rate * tau) - r * np.sin(OMEGA * tau)) / (1 - r**2)


def test_half_sine_pulse_undamped():
    duration, start = 0.013, 0.2
    x, v, a = sdof_response(half_sine(duration, start))
    tau = TIMES - start
    rate = np.pi / duration
    want = np.where(tau < 0, 0.0, _undamped_sine(rate, np.maximum(tau, 0))
                    + np.where(tau >= duration, _undamped_sine(rate, np.maximum(tau - duration, 0)), 0.0))
    assert_history(x, want)
    load = np.where((tau >= 0) & (tau < duration), F * np.sin(rate * np.maximum(tau, 0)), 0.0)
    assert_history(a, load / M_SDOF - OMEGA**2 * x)


def test_harmonic_from_rest_with_damping():
    zeta, rate, phase = 0.05, 0.8 * OMEGA, 0.4
    x, _, _ = sdof_response(harmonic(rate / (2 * np.pi), phase), damping=(2 * zeta * OMEGA, 0.0))
    amplitude = F / M_SDOF / np.hypot(OMEGA**2 - rate**2, 2 * zeta * OMEGA * rate)
    lag = np.arctan2(2 * zeta * OMEGA * rate, OMEGA**2 - rate**2)
    steady = amplitude * np.sin(rate * TIMES + phase - lag)
    wd = OMEGA * np.sqrt(1 - zeta**2)
    A = -amplitude * np.sin(phase - lag)
    B = (zeta * OMEGA * A - amplitude * rate * np.cos(phase - lag)) / wd
    transient = np.exp(-zeta * OMEGA * TIMES) * (A * np.cos(wd * TIMES) + B * np.sin(wd * TIMES))
    assert_history(x, steady + transient)


def test_tabulated_ramp_and_hold():
    rise = 0.021
    x, _, _ = sdof_response(table([0.0, rise], [0.0, 1.0], hold=True))

    def ramp(t):
        t = np.maximum(t, 0.0)
        return F / K_SDOF * (t / rise - np.sin(OMEGA * t) / (OMEGA * rise))

    assert_history(x, ramp(TIMES) - ramp(TIMES - rise))


def test_tabulated_samples_end_at_zero():
    """A triangle given by samples, then nothing: free vibration afterwards."""
    function = table([0.01, 0.02, 0.04], [0.0, 1.0, 0.0])
    assert function(0.015) == pytest.approx(0.5)
    assert function(0.05) == 0.0
    x, v, a = sdof_response(function)
    after = TIMES > 0.04
    energy = 0.5 * K_SDOF * x[after] ** 2 + 0.5 * M_SDOF * v[after] ** 2
    assert np.ptp(energy) < 1e-10 * energy.max()


def test_undamped_step_between_output_times():
    """F/k (1 − cos ωτ) from a start that falls between two output times."""
    start = 0.10037
    x, v, a = sdof_response(step(start))
    tau = np.maximum(TIMES - start, 0.0)
    assert_history(x, F / K_SDOF * (1 - np.cos(OMEGA * tau)))
    assert_history(v, F / K_SDOF * OMEGA * np.sin(OMEGA * tau))
    assert_history(a, np.where(TIMES >= start, F / M_SDOF * np.cos(OMEGA * tau), 0.0))


def _expm_reference(omega, rate, function, times):
    """(q, q̇, q̈) by one matrix exponential per output time and mode: y' = G y,
    y = (q, q̇, g, g'), carried from each segment start (the reference for the
    propagators applied by doubling)."""
    def generator(nu):
        G = np.zeros((omega.size, 4, 4))
        G[:, 0, 1], G[:, 1, 0], G[:, 1, 1], G[:, 1, 2], G[:, 2, 3], G[:, 3, 2] = 1, -omega**2, -rate, 1, 1, -nu
        return G

    state, starts = np.zeros((omega.size, 4)), []
    for j, start in enumerate(function.starts):
        if j:
            tau = start - function.starts[j - 1]
            state = np.einsum("nij,nj->ni", scipy.linalg.expm(generator(function.nu[j - 1]) * tau), state)
        state[:, 1] += function.kicks[j]
        state[:, 2], state[:, 3] = function.values[j], function.slopes[j]
        starts.append(state.copy())
    out = np.zeros((times.size, omega.size, 4))
    for i, t in enumerate(times):
        j = np.searchsorted(function.starts, t, side="right") - 1
        if j >= 0:
            carry = scipy.linalg.expm(generator(function.nu[j]) * (t - function.starts[j]))
            out[i] = np.einsum("nij,nj->ni", carry, starts[j])
    return out[..., 0], out[..., 1], out[..., 2] - rate * out[..., 1] - omega**2 * out[..., 0]


@pytest.mark.parametrize("function", [
    step(0.0123), impulse(0.3), half_sine(0.05, 0.1), harmonic(40.0 / (2 * np.pi), 0.3, 0.05),
    table([0.01, 0.2, 0.5, 0.9], [0.0, 1.0, -2.0, 0.5]), table([0.0, 0.2], [1.0, 3.0], hold=True)],
    ids=lambda function: function.kind)
def test_propagators_equal_one_exponential_per_time(function):
    """Rigid-body (ω = 0, with and without damping), undamped, under-, critically and
    overdamped modes, a stiff one (ω² τ up to 2e7), and a harmonic load at resonance
    (ω = 40 rad/s, undamped)."""
    omega = np.array([0.0, 0.0, 3.0, 10.0, 40.0, 40.0, 200.0, 3000.0])
    rate = np.array([0.0, 0.5, 0.0, 20.0, 80.0, 0.0, 1.0, 30.0])
    times = np.linspace(0.0, 2.0, 201)
    for got, want in zip(unit_response(omega, rate, function, times),
                         _expm_reference(omega, rate, function, times)):
        assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()


def test_unequal_output_steps_are_refused():
    with pytest.raises(ValueError, match="equal steps"):
        unit_response([OMEGA], [0.0], step(), [0.0, 0.1, 0.3])


def test_frf_peak_and_half_power_points_with_damping_ratio():
    """Receptance of one mode with ratio ζ: the peak 1 / (2ζ√(1−ζ²) k) at ω√(1−2ζ²), and
    half of its power at Ω² = ω² (1 − 2ζ² ∓ 2ζ√(1−ζ²)), a bandwidth of about 2ζω."""
    zeta = 0.02
    modes = mode_shapes(sdof(), count=1)
    peak_at = OMEGA * np.sqrt(1 - 2 * zeta**2)
    half_power = OMEGA * np.sqrt(1 - 2 * zeta**2 + np.array([-1.0, 1.0]) * 2 * zeta * np.sqrt(1 - zeta**2))
    near = peak_at * (1 + np.array([-1e-4, 1e-4]))
    at = np.r_[peak_at, half_power, near] / (2 * np.pi)
    H = np.abs(frf(modes, "p", np.eye(6)[0], at, ["p"], damping_ratio=zeta).receptance[:, 0, 0])
    peak = 1 / (2 * zeta * np.sqrt(1 - zeta**2) * K_SDOF)
    assert H[0] == pytest.approx(peak, rel=1e-12)
    np.testing.assert_allclose(H[1:3], peak / np.sqrt(2), rtol=1e-12)
    assert np.all(H[3:] < H[0])
    assert half_power[1] - half_power[0] == pytest.approx(2 * zeta * OMEGA, rel=2 * zeta**2)


def test_damping_ratios_must_fit_and_stand_alone():
    modes = mode_shapes(sdof(), count=1)
    with pytest.raises(DampingRatioError, match="not both"):
        frf(modes, "p", np.eye(6)[0], [1.0], damping=(0.1, 0.0), damping_ratio=0.02)
    with pytest.raises(DampingRatioError, match="one for each of the 1"):
        frf(modes, "p", np.eye(6)[0], [1.0], damping_ratio=[0.02, 0.03])
    with pytest.raises(DampingRatioError, match=">= 0"):
        frf(modes, "p", np.eye(6)[0], [1.0], damping_ratio=-0.01)


# --- two-mass chain: hand-written M, K ------------------------------------------

K_CHAIN, M_CHAIN, DAMPING = 1000.0, 2.0, (0.3, 2e-4)
M_HAND = np.diag([3 * M_CHAIN, M_CHAIN])
K_HAND = K_CHAIN * np.array([[2.0, -1.0], [-1.0, 2.0]])


def chain():
    """fixed–k–3m–k–m–k–fixed along x; every translation direction is this 2-DOF chain."""
    return spring_mass_chain(K_CHAIN, M_CHAIN, DAMPING)


def test_frf_matches_direct_harmonic_solve():
    modes = mode_shapes(chain(), count=6)
    force = np.array([1.0, -0.5, 0.25])
    frequencies = np.linspace(0.5, 12.0, 200)
    result = frf(modes, "b1", np.r_[force, np.zeros(3)], frequencies, ["a1", "b2"], DAMPING)
    alpha, beta = DAMPING
    for f, H in zip(frequencies, result.receptance):
        W = 2 * np.pi * f
        dynamic = K_HAND - W**2 * M_HAND + 1j * W * (alpha * M_HAND + beta * K_HAND)
        direct = np.linalg.solve(dynamic, np.array([[1.0], [0.0]]))[:, 0] * force[:, None]  # (3, 2)
        np.testing.assert_allclose(H[:, :3], direct.T, rtol=1e-10, atol=1e-12 * np.abs(direct).max())
        assert np.abs(H[:, 3:]).max() < 1e-12 * np.abs(direct).max()
    np.testing.assert_allclose(result.mobility, 2j * np.pi * frequencies[:, None, None] * result.receptance)


def test_chain_impulse_matches_state_space_solution():
    """All six modes of the chain against expm of its hand-written first-order system."""
    modes = mode_shapes(chain(), count=6)
    kick = 2.0  # N s on m2 along y
    load = PointLoad("b2", np.array([0.0, kick, 0.0]), np.zeros(3), impulse(0.0))
    times = np.linspace(0.0, 2.0, 401)
    result = modal_response(modes, [load], times, ["b1", "b2"], DAMPING)
    alpha, beta = DAMPING
    minv = np.linalg.inv(M_HAND)
    system = np.block([[np.zeros((2, 2)), np.eye(2)],
                       [-minv @ K_HAND, -minv @ (alpha * M_HAND + beta * K_HAND)]])
    start = np.r_[0.0, 0.0, minv @ np.array([0.0, kick])]
    direct = np.array([scipy.linalg.expm(system * t) @ start for t in times])
    assert_history(result.displacement[:, :, 1], direct[:, :2])
    assert_history(result.velocity[:, :, 1], direct[:, 2:])
    assert np.abs(result.displacement[:, :, [0, 2]]).max() < 1e-12 * np.abs(direct).max()


def test_frf_with_a_ratio_per_mode_matches_direct_solve():
    """Modal damping ratios, one per mode: C = M Φ diag(2 ζ_k ω_k) Φᵀ M from the
    eigenvectors of the hand-written M, K (mass-normalised), solved directly."""
    modes = mode_shapes(chain(), count=6)
    lam, phi = scipy.linalg.eigh(K_HAND, M_HAND)
    zeta_1d = np.array([0.01, 0.05])
    zeta = np.repeat(zeta_1d, 3)  # each frequency thrice: x, y, z
    C = M_HAND @ phi @ np.diag(2 * zeta_1d * np.sqrt(lam)) @ phi.T @ M_HAND
    frequencies = np.linspace(0.5, 8.0, 120)
    result = frf(modes, "b2", np.eye(6)[2], frequencies, ["a1", "b2"], damping_ratio=zeta)
    for f, H in zip(frequencies, result.receptance):
        W = 2 * np.pi * f
        direct = np.linalg.solve(K_HAND - W**2 * M_HAND + 1j * W * C, np.array([0.0, 1.0]))
        np.testing.assert_allclose(H[:, 2], direct, rtol=1e-10)


# --- the load file ----------------------------------------------------------------

LOADS = """\
[[load]]
point = "b2"
force = [0.0, 10.0, 0.0]
time = { kind = "half_sine", duration = 0.01, start = 0.1 }

[[load]]
point = "b1"
moment = [0.0, 0.0, 1.0]
time = { kind = "table", time = [0.0, 0.1, 0.2], value = [0.0, 5.0, 0.0] }

[output]
points = ["b1", "b2"]
duration = 0.5
step = 0.001
modes = 6
"""


def test_load_file_round_trip(tmp_path):
    path = tmp_path / "loads.toml"
    path.write_text(LOADS)
    model = chain()
    case = load_loads(path, model)
    assert [load.point for load in case.loads] == ["b2", "b1"]
    assert case.times.size == 501 and case.times[-1] == pytest.approx(0.5)
    assert case.points == ("b1", "b2") and case.modes == 6
    assert case.loads[1].time(0.05) == pytest.approx(2.5)
    result = respond(model, case)
    assert result.displacement.shape == (501, 2, 6)
    assert set(result.to_dict()) == {"times", "points", "displacement", "velocity", "acceleration",
                                     "units", "elastic_modes", "rigid_body_modes", "frequencies_hz",
                                     "static_correction"}


@pytest.mark.parametrize("edit, key, words", [
    (('"half_sine"', '"half_cosine"'), "time", "kind must be one of"),
    (('point = "b2"', 'point = "b3"'), "point", "unknown point"),
    (("duration = 0.01,", ""), "duration", "missing required key"),
    (("[0.0, 0.1, 0.2]", "[0.0, 0.2, 0.1]"), "time", "increase strictly"),
    (("force = [0.0, 10.0, 0.0]", "force = [0.0, 10.0]"), "force", "array of 3 numbers"),
    (("modes = 6", "modes = 0"), "modes", "positive integer"),
])
def test_load_file_errors_name_load_and_key(tmp_path, edit, key, words):
    path = tmp_path / "loads.toml"
    path.write_text(LOADS.replace(*edit))
    with pytest.raises(ModelError) as error:
        load_loads(path, chain())
    assert error.value.key == key
    assert words in error.value.message
    assert str(path) in str(error.value)


def test_frf_matches_the_finite_element_modal_sum():
    """Same truncation (12 modes) on both routes: the modal data agree, not just the frequencies."""
    from test_modes import tree_modes_both_routes

    model, modes, fe, lam, X = tree_modes_both_routes(12)
    vector, damping = np.r_[0.0, 0.3, 1.0, 0.0, 0.0, 0.0], (0.5, 1e-4)
    frequencies = np.array([5.0, 20.0, 40.0, 75.0])
    points = list(model.points)
    got = frf(modes, "tip", vector, frequencies, points, damping).receptance
    load = np.zeros(fe.n_full)
    load[fe.dof_index.point("tip")] = vector
    W = 2 * np.pi * frequencies[:, None]
    modal = (X.T @ (fe.T.T @ load)) / (lam - W**2 + 1j * W * (damping[0] + damping[1] * lam))
    full = (fe.T @ (X @ modal.T)).T  # (n_f, n_full)
    want = np.stack([full[:, fe.dof_index.point(p)] for p in points], axis=1)
    assert np.abs(got - want).max() < 1e-6 * np.abs(want).max()


# --- the commands -----------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[1]
CHAIN_FILE = ROOT / "models/spring_mass_chain.toml"
CANTILEVER_FILE = ROOT / "models/cantilever_tip_mass.toml"
CANTILEVER_STEP = ROOT / "models/loads/cantilever_step.toml"


def command(capsys, *argv):
    """(exit status, stdout, stderr) of the linmstmm command line."""
    status = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.fixture
def chain_step(tmp_path):
    """A step on the chain's m1 along y, 20 modes asked for (the chain has 6)."""
    path = tmp_path / "chain_step.toml"
    path.write_text('[[load]]\npoint = "b1"\nforce = [0.0, 10.0, 0.0]\ntime = { kind = "step" }\n\n'
                    '[output]\npoints = ["b1"]\nduration = 0.2\nmodes = 20\n')
    return path


@pytest.mark.parametrize("quantity", ["displacement", "velocity", "acceleration"])
def test_response_units_and_mode_count_in_table_and_json(capsys, chain_step, quantity):
    translation, rotation = {"displacement": ("m", "rad"), "velocity": ("m/s", "rad/s"),
                             "acceleration": ("m/s^2", "rad/s^2")}[quantity]
    status, out, _ = command(capsys, "response", CHAIN_FILE, chain_step, "--quantity", quantity)
    assert status == 0
    assert "(6 elastic modes (20 asked" in out.splitlines()[0]
    header = out.splitlines()[2].split()
    assert header == ["point", "x", f"[{translation}]", "y", f"[{translation}]", "z", f"[{translation}]",
                      "rx", f"[{rotation}]", "ry", f"[{rotation}]", "rz", f"[{rotation}]"]
    status, out, _ = command(capsys, "response", CHAIN_FILE, chain_step, "--json", "--quantity", quantity)
    data = json.loads(out)
    assert data["modes"] == data["elastic_modes"] == 6 and data["modes_asked"] == 20
    assert data["units"][quantity] == [translation] * 3 + [rotation] * 3 and data["units"]["times"] == "s"


@pytest.mark.parametrize("direction, per", [("z", "N"), ("ry", "(N m)")])
def test_frf_units_in_table_and_json(capsys, direction, per):
    argv = ("frf", CANTILEVER_FILE, "--point", "tip", "--direction", direction, "--fmax", "60",
            "--frequencies", "100", "--zeta", "0.02")
    status, out, _ = command(capsys, *argv)
    assert status == 0 and "modal damping ratio 0.02" in out
    rows = out.splitlines()[3:]
    assert out.splitlines()[2].split() == ["point", "component", "largest", "|H|", "unit", "at", "[Hz]"]
    assert {row.split()[1] for row in rows} == {"z", "ry"}  # the load's own plane
    for row in rows:
        unit = f"{'m' if row.split()[1] in ('x', 'y', 'z') else 'rad'}/{per}"
        assert f" {unit} " in row and row.count("/") == 1
    data = json.loads(command(capsys, *argv, "--json")[1])
    assert data["receptance_units"] == [f"m/{per}"] * 3 + [f"rad/{per}"] * 3
    assert data["damping_ratio"] == [0.02] and data["damping"] is None


def dashpot_chain(tmp_path):
    """The bundled chain with a 20 N s/m dashpot beside its middle spring."""
    text = CHAIN_FILE.read_text()
    middle = 'ends = ["b1", "a2"]\nk = [1000.0, 1000.0, 1000.0, inf, inf, inf]\n'
    assert middle in text
    path = tmp_path / "dashpot_chain.toml"
    path.write_text(text.replace(middle, middle + "c = [20.0, 20.0, 20.0, 0.0, 0.0, 0.0]\n"))
    return path


def test_zeta_that_does_not_fit_the_modes_exits_2(capsys):
    status, _, err = command(capsys, "frf", CHAIN_FILE, "--point", "b1", "--direction", "y", "--fmax", "10",
                             "--zeta", "0.01,0.02")
    assert status == 2 and "key '--zeta'" in err and "each of the 6" in err
