"""The time response with spring dashpots (linmstmm/modal_dashpots.py): the modal
equations they couple, solved together, against references independent of the
transfer matrices — the two-mass chain's closed state-space solution, and the
FE route's mass, stiffness and dashpot matrices of a beam solved the same way."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from builders import cantilever_with_tip_dashpot

from linmstmm import cli, load_model
from linmstmm.fe.assembly import assemble
from linmstmm.fe.damping import dashpot_matrix
from linmstmm.loads import LoadCase, PointLoad, harmonic, step
from linmstmm.modal_dashpots import DefectiveDampingError, coupled_unit_response
from linmstmm.response import respond

ROOT = Path(__file__).resolve().parents[1]
TIMES = np.linspace(0.0, 0.6, 601)


def state_space_response(M, K, C, force, times, start):
    """Displacements (n_t, n) of M ẍ + C ẋ + K x = force·step(t − start) from rest,
    through the eigenvalues of the first-order system (dense, exact to rounding)."""
    n = K.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    lam, V = np.linalg.eig(A)
    beta = np.linalg.solve(V, np.r_[np.zeros(n), Minv @ force])
    tau = np.maximum(times - start, 0.0)[:, None]
    return (((np.expm1(lam * tau) / lam) * beta) @ V.T)[:, :n].real


def test_the_chain_with_a_dashpot_follows_its_closed_state_space_solution():
    """models/dashpot_chain.toml along y: masses 6 and 2 kg, springs of 1000 N/m to the
    ground and between them, 20 N s/m beside the middle one; all 6 modes in the sum,
    so the modal solution is the whole solution."""
    model = load_model(ROOT / "models" / "dashpot_chain.toml")
    load = PointLoad("b2", np.array([0.0, 10.0, 0.0]), np.zeros(3), step(0.05))
    result = respond(model, LoadCase((load,), TIMES, ("b1", "b2"), 6))
    M, K = np.diag([6.0, 2.0]), np.array([[2000.0, -1000.0], [-1000.0, 2000.0]])
    C = np.array([[20.0, -20.0], [-20.0, 20.0]])
    expected = state_space_response(M, K, C, np.array([0.0, 10.0]), TIMES, 0.05)
    got = result.displacement[:, :, 1]
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))
    undamped = respond(load_model(ROOT / "models" / "spring_mass_chain.toml"),
                       LoadCase((load,), TIMES, ("b1", "b2"), 6)).displacement[:, :, 1]
    assert np.max(np.abs(undamped - expected)) > 0.1 * np.max(np.abs(expected))  # the dashpot acts


@pytest.fixture(scope="module")
def tip_damper(tmp_path_factory):
    return cantilever_with_tip_dashpot(tmp_path_factory.mktemp("damper"))


def test_a_beam_with_a_tip_dashpot_converges_on_the_fe_state_space_solution(tip_damper):
    """Reference: the FE route's K, M and dashpot C on 32 elements per beam (8 and 16
    differ from it by 7e-5 and 8e-6), solved as a first-order system. The modal sum
    with its static correction converges on it as modes are added: 2e-4 with 4,
    7e-7 with 20."""
    load = PointLoad("tip", np.array([0.0, 30.0, -100.0]), np.zeros(3), step(0.01))
    fe = assemble(tip_damper, 32)
    force = np.zeros(fe.n_full)
    force[fe.dof_index.point("tip")] = np.r_[load.force, load.moment]
    states = state_space_response(fe.M.toarray(), fe.K.toarray(), dashpot_matrix(tip_damper, fe).toarray(),
                                  fe.T.T @ force, TIMES, 0.01)
    expected = (states @ fe.T.T)[:, fe.dof_index.point("tip")][:, :3]
    scale = np.max(np.abs(expected))
    errors = [np.max(np.abs(respond(tip_damper, LoadCase((load,), TIMES, ("tip",), modes)).displacement[:, 0, :3]
                            - expected)) / scale for modes in (4, 20)]
    assert errors[1] <= 2e-6 and errors[1] < errors[0] / 50


def test_a_harmonic_load_settles_to_the_fe_routes_complex_receptance(tip_damper):
    """After the transients die out (the dashpot damps every z-bending mode the load
    excites), the amplitude at the tip is |H(Ω)| of the FE route's direct complex solve."""
    from linmstmm.fe.damping import harmonic_receptance

    times = np.linspace(0.0, 4.0, 8001)
    load = PointLoad("tip", np.array([0.0, 0.0, 1.0]), np.zeros(3), harmonic(20.0))
    history = respond(tip_damper, LoadCase((load,), times, ("tip",), 20)).displacement[:, 0, 2]
    expected = abs(harmonic_receptance(tip_damper, "tip", np.r_[0, 0, 1.0, 0, 0, 0], [20.0], ["tip"], 32)[0, 0, 2])
    assert np.max(np.abs(history[times > 3.0])) == pytest.approx(expected, rel=1e-3)


def test_two_modes_a_dashpot_makes_critically_damped_at_one_rate_are_refused():
    """ω = 1 and 1 with a coupling that makes the 4×4 system one defective eigenvalue."""
    with pytest.raises(DefectiveDampingError, match="coincide"):
        coupled_unit_response([1.0, 1.0], [2.0, 2.0], np.array([[0.0, 1e-30], [1e-30, 0.0]]), [1.0, 1.0],
                              step(0.0), TIMES)


def test_the_command_line_answers_a_model_with_a_dashpot(capsys, tmp_path):
    loads = tmp_path / "step.toml"
    loads.write_text('[[load]]\npoint = "b2"\nforce = [0.0, 10.0, 0.0]\ntime = { kind = "step" }\n\n'
                     '[output]\npoints = ["b2"]\nduration = 5.0\nstep = 0.01\nmodes = 6\n')
    assert cli.main(["response", str(ROOT / "models" / "dashpot_chain.toml"), str(loads)]) == 0
    assert "b2" in capsys.readouterr().out
