"""Mode shapes and augmented eigenvectors (linmstmm.modes) against closed forms.

The reference shapes are the classical cantilever functions
φ(x) = cosh βx − cos βx − σ (sinh βx − sin βx), σ = (cosh βL + cos βL)/(sinh βL + sin βL),
with ∫₀ᴸ φ² dx = L and |φ(L)| = 2 (Blevins, table 8-1), so the mass-normalised
shape is φ/√(ρAL) and the shape with unit tip deflection has modal mass ρAL/4.
Orthogonality is checked on models that couple every kind of element.
"""
from __future__ import annotations

import json

import mpmath as mp
import numpy as np
import pytest
from builders import fixed, make_beam, make_rigid, make_spring, single_beam_model

from linmstmm.model import Model
from linmstmm.modes import mac_matrix, mode_shapes
from linmstmm.solve import frequency_finder

CANTILEVER_ROOTS = [float(mp.findroot(lambda x: mp.cos(x) * mp.cosh(x) + 1, x0))
                    for x0 in (1.8751, 4.6941, 7.8548, 10.9955)]


def cantilever_shape(beta_L, s):
    """φ(s/L) of the cantilever mode with root βL, at relative stations s (0..1)."""
    b = beta_L * s
    sigma = (np.cosh(beta_L) + np.cos(beta_L)) / (np.sinh(beta_L) + np.sin(beta_L))
    return np.cosh(b) - np.cos(b) - sigma * (np.sinh(b) - np.sin(b))


def cantilever_slope(beta_L, s, L):
    """dφ/dx of :func:`cantilever_shape`, 1/m."""
    b = beta_L * s
    sigma = (np.cosh(beta_L) + np.cos(beta_L)) / (np.sinh(beta_L) + np.sin(beta_L))
    return beta_L / L * (np.sinh(b) + np.sin(b) - sigma * (np.cosh(b) - np.cos(b)))


def _cantilever(**options):
    """Steel cantilever along x, L = 2 m, bending x-y (Iz) softer than x-z (Iy)."""
    return single_beam_model(fixed(), None, length=2.0, Iz=2e-7, Iy=7e-7, **options)


@pytest.mark.parametrize("engine", ["numpy", "compiled"])  # compiled: its Ū_all gives the null spaces
def test_cantilever_shapes_match_closed_form(engine):
    model = _cantilever(axial=False, torsion=False)
    beam = model.beams[0]
    modes = mode_shapes(model, count=8, stations=41, engine=engine)
    field = modes.beam_fields["beam"]
    s = field.stations / beam.length
    rhoAL = beam.rho * beam.A * beam.length
    plane_xy = np.abs(field.displacements[:, :, 1]).max(axis=1) > np.abs(field.displacements[:, :, 2]).max(axis=1)
    assert plane_xy.sum() >= len(CANTILEVER_ROOTS)
    worst = 0.0
    for k, beta_L in zip(np.flatnonzero(plane_xy), CANTILEVER_ROOTS):
        want_omega = beta_L**2 * np.sqrt(beam.E * beam.Iz / (beam.rho * beam.A * beam.length**4))
        assert modes.omega[k] == pytest.approx(want_omega, rel=1e-11)
        want = cantilever_shape(beta_L, s) / np.sqrt(rhoAL)
        got = field.displacements[k, :, 1]
        sign = np.sign(got @ want)
        worst = max(worst, np.abs(sign * got - want).max() / np.abs(want).max())
        slope = sign * field.displacements[k, :, 5]  # θz = v'
        want_slope = cantilever_slope(beta_L, s, beam.length) / np.sqrt(rhoAL)
        np.testing.assert_allclose(slope, want_slope, atol=1e-8 * np.abs(want_slope).max())
        others = np.delete(field.displacements[k], [1, 5], axis=1)
        assert np.abs(others).max() < 1e-12 * np.abs(want).max()
    assert worst < 1e-8


def test_modal_mass_with_unit_tip_deflection_is_quarter_beam_mass():
    model = _cantilever(axial=False, torsion=False)
    beam = model.beams[0]
    modes = mode_shapes(model, count=6, normalization="max")
    np.testing.assert_allclose(modes.modal_mass, beam.rho * beam.A * beam.length / 4, rtol=1e-10)
    np.testing.assert_allclose(np.abs(modes.point_displacements["b"][:, :3]).max(axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(modes.modal_stiffness, modes.omega**2 * modes.modal_mass)


def test_torsion_and_axial_modal_masses():
    """Fixed-free rod and shaft: φ = sin((2n−1)πx/2L), ∫ρA φ² = ρAL/2 with unit tip amplitude."""
    L = 3.0
    model = single_beam_model(fixed(), None, length=L, Iz=1.0, Iy=1.0, J=2e-7, Ip=4e-7)
    beam = model.beams[0]
    modes = mode_shapes(model, count=4, normalization="max")
    tip = modes.point_displacements["b"]
    axial = np.abs(tip[:, 0]) > 0.5
    np.testing.assert_allclose(modes.modal_mass[axial], beam.rho * beam.A * L / 2, rtol=1e-10)
    np.testing.assert_allclose(modes.modal_mass[~axial], beam.rho * beam.Ip * L / 2, rtol=1e-10)
    assert modes.energy_error < 1e-10


def cantilever_tip_body():
    """Cantilever with an eccentric tip body (full inertia tensor): everything couples."""
    points = {"root": np.zeros(3), "tip": np.array([2.0, 0.0, 0.0])}
    inertia = np.array([[0.3, 0.02, -0.01], [0.02, 0.2, 0.03], [-0.01, 0.03, 0.25]])
    return Model("tip body", points,
                 rigids=(make_rigid("payload", ["tip"], 5.0, [2.1, 0.05, 0.02], inertia),),
                 beams=(make_beam("arm", "root", "tip", points, Iz=2e-7, Iy=3e-7),),
                 boundary={"root": fixed()})


def tree():
    """A hub (rigid, three ports) on a vertical post; an arm beam, and a spring carrying a pod."""
    points = {"g": np.zeros(3), "p1": np.array([0.0, 0.0, 1.0]), "p2": np.array([0.3, 0.0, 1.1]),
              "p3": np.array([-0.2, 0.1, 1.0]), "q3": np.array([-0.2, 0.1, 1.0]),
              "tip": np.array([1.5, 0.2, 1.1])}
    return Model(
        "tree", points,
        rigids=(make_rigid("hub", ["p1", "p2", "p3"], 20.0, [0.0, 0.02, 1.05], [0.4, 0.5, 0.3]),
                make_rigid("pod", ["q3"], 3.0, [-0.25, 0.1, 0.9], [0.02, 0.03, 0.01])),
        beams=(make_beam("post", "g", "p1", points, A=2e-3, Iy=8e-7, Iz=6e-7, J=1e-6),
               make_beam("arm", "p2", "tip", points, Iy=1e-7, Iz=2e-7, J=2e-7)),
        springs=(make_spring("mount", "p3", "q3", [2e5, 3e5, 1e5, 4e3, np.inf, 5e3],
                             axes=np.array([[0.0, 0.6, 0.8], [0.0, 0.8, -0.6], [-1.0, 0.0, 0.0]])),),
        boundary={"g": fixed()})


def loop():
    """A post carries a frame; two beams from the frame to a bar close a loop."""
    points = {"g": np.zeros(3), "a": np.array([0.0, 0.0, 1.0]), "b1": np.array([0.0, -0.5, 1.0]),
              "b2": np.array([0.0, 0.5, 1.0]), "c1": np.array([0.8, -0.5, 1.2]),
              "c2": np.array([0.8, 0.5, 1.2]), "d": np.array([0.8, 0.5, 1.2])}
    return Model(
        "loop", points,
        rigids=(make_rigid("frame", ["a", "b1", "b2"], 8.0, [0.0, 0.0, 1.0], [0.5, 0.1, 0.5]),
                make_rigid("bar", ["c1", "d"], 4.0, [0.8, 0.0, 1.2], [0.3, 0.05, 0.3])),
        beams=(make_beam("post", "g", "a", points, A=2e-3, Iy=8e-7, Iz=6e-7, J=1e-6),
               make_beam("left", "b1", "c1", points),
               make_beam("right", "b2", "c2", points, Iy=3e-7)),
        springs=(make_spring("joint", "c2", "d", [1e6, 1e6, 1e6, 2e3, 3e3, np.inf]),),
        boundary={"g": fixed()})


def round_tube():
    """Round tube cantilever with a symmetric tip mass: every bending frequency is double."""
    points = {"root": np.zeros(3), "tip": np.array([0.0, 0.0, 1.5])}
    return Model("round tube", points,
                 rigids=(make_rigid("cap", ["tip"], 2.0, [0.0, 0.0, 1.6], [0.01, 0.01, 0.02]),),
                 beams=(make_beam("tube", "root", "tip", points, A=8e-4, Iy=4e-7, Iz=4e-7,
                                  J=8e-7),),
                 boundary={"root": fixed()})


def test_fast_path_sees_a_double_root_at_the_edge_between_two_scan_chunks():
    """The round tube's first (double) root, 126.5 rad/s, lies 1 % below the top of
    a scan chunk (128 rad/s): the chunks share their edge points, so the fast path
    finds it as the full search does, without falling back."""
    _, finder, _ = frequency_finder(round_tube())
    fast = finder._scan_ahead(15, None)
    assert fast is not None
    np.testing.assert_allclose(fast, finder._search(15, None), rtol=1e-12)
    assert fast[0] == fast[1] and 125 < fast[0] < 128 < fast[2]


MODELS = {"tip body": cantilever_tip_body, "tree": tree, "loop": loop, "round tube": round_tube,
          "clamped-clamped, axially rigid (indeterminate)":
              lambda: single_beam_model(fixed(), fixed(), Iz=2e-7, Iy=5e-7, axial=False),
          "free-free (rigid-body modes)": lambda: single_beam_model(None, None, Iz=2e-7, Iy=5e-7)}


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
@pytest.mark.parametrize("name", sorted(MODELS))
def test_augmented_eigenvectors_are_orthogonal(name, engine):
    modes = mode_shapes(MODELS[name](), count=10, engine=engine)
    assert modes.mass_orthogonality_error < 1e-9
    assert modes.stiffness_orthogonality_error < 1e-9
    assert modes.energy_error < 1e-9  # strain energy = ω² × kinetic: an independent check
    np.testing.assert_allclose(modes.modal_mass, 1.0, rtol=1e-12)
    assert modes.omega.size >= 10


def test_free_beam_has_six_rigid_body_modes_first():
    modes = mode_shapes(single_beam_model(None, None, Iz=2e-7, Iy=5e-7), count=4)
    assert modes.rigid_body_modes == 6
    assert np.all(modes.omega[:6] == 0) and np.all(modes.omega[6:] > 0)
    stiffness = modes.orthogonality_stiffness[:6, :6]
    assert np.abs(stiffness).max() < 1e-9 * modes.omega[6] ** 2


def test_repeated_frequencies_give_an_axis_aligned_eigenspace():
    modes = mode_shapes(round_tube(), count=6)
    pairs = modes.omega[:4].reshape(2, 2)
    np.testing.assert_allclose(pairs[:, 0], pairs[:, 1], rtol=1e-12)
    tip = modes.point_displacements["tip"][:4, :3]
    # one mode bends along x, the other along y; none along both
    assert np.all(np.sort(np.abs(tip[:, :2]), axis=1)[:, 0] < 1e-9 * np.abs(tip).max())


def test_modes_do_not_depend_on_the_root():
    """Rooted at the free arm tip, every beam and body is traversed the other way."""
    model = tree()
    a = mode_shapes(model, count=6, stations=7)
    b = mode_shapes(model, count=6, stations=7, root="tip")
    np.testing.assert_allclose(a.omega, b.omega, rtol=1e-10)
    assert np.diag(a.mac(b.shape_matrix())).min() > 1 - 1e-10
    for name in ("post", "arm"):
        np.testing.assert_allclose(b.beam_fields[name].displacements, a.beam_fields[name].displacements,
                                   atol=1e-9 * np.abs(a.beam_fields[name].displacements).max())


def test_mac_matrix():
    a = np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    mac = mac_matrix(a, a)
    np.testing.assert_allclose(mac, [[1.0, 0.5], [0.5, 1.0]])
    np.testing.assert_allclose(mac_matrix(a, -3 * a), mac)


def test_result_serialises_to_json():
    modes = mode_shapes(cantilever_tip_body(), count=3, stations=5)
    data = json.loads(json.dumps(modes.to_dict()))
    assert len(data["frequencies_hz"]) == 3
    assert np.array(data["beam_fields"]["arm"]["displacements"]).shape == (3, 5, 6)
    assert set(data["point_displacements"]) == {"root", "tip"}
    assert np.array(data["com_displacements"]["payload"]).shape == (3, 6)


def test_quadrature_is_converged():
    """The Gram matrices do not change when the quadrature is refined."""
    import linmstmm.mode_fields as modes_module

    model = tree()
    coarse = mode_shapes(model, count=8)
    saved = modes_module.EXTRA_QUADRATURE_POINTS
    try:
        modes_module.EXTRA_QUADRATURE_POINTS = saved + 40
        fine = mode_shapes(model, count=8)
    finally:
        modes_module.EXTRA_QUADRATURE_POINTS = saved
    np.testing.assert_allclose(coarse.orthogonality_mass, fine.orthogonality_mass, atol=1e-12)
    np.testing.assert_allclose(coarse.orthogonality_stiffness / coarse.omega[-1] ** 2,
                               fine.orthogonality_stiffness / fine.omega[-1] ** 2, atol=1e-12)


def tree_modes_both_routes(count):
    """(model, MSTMM modes, FE model, FE eigenvalues, FE modes) of :func:`tree`, 24 elements per beam."""
    from linmstmm.fe import assemble, fe_modes

    model = tree()
    fe = assemble(model, 24)
    lam, X, _ = fe_modes(fe, count)
    return model, mode_shapes(model, count=count), fe, lam, X


def test_shapes_match_the_finite_element_route():
    """MAC > 0.9999 per mode against the FE route (Hermite beams, 24 elements per beam)."""
    model, modes, fe, lam, X = tree_modes_both_routes(8)
    full = fe.T @ X
    points = list(model.points)
    fe_shapes = np.stack([np.concatenate([full[fe.dof_index.point(p), k] for p in points])
                          for k in range(lam.size)])
    np.testing.assert_allclose(modes.omega, np.sqrt(lam), rtol=1e-6)
    assert np.diag(modes.mac(fe_shapes, points)).min() > 0.9999


def test_one_default_normalisation_for_the_function_and_the_command(capsys):
    """``mode_shapes`` and ``linmstmm modes`` both scale to unit modal mass unless told
    otherwise; ``--normalization max`` gives the same shapes over √M_k."""
    from pathlib import Path

    from linmstmm.cli import main
    from linmstmm.model import load_model

    path = str(Path(__file__).resolve().parents[1] / "models" / "cantilever_tip_mass.toml")
    runs = {}
    for option in ([], ["--normalization", "max"]):
        assert main(["modes", path, "--count", "3", "--json", *option]) == 0
        data = json.loads(capsys.readouterr().out)
        runs[data["normalization"]] = data
    api = mode_shapes(load_model(path), count=3)
    assert sorted(runs) == ["mass", "max"] and api.normalization == "mass"
    np.testing.assert_allclose(runs["mass"]["modal_mass"], 1.0, rtol=1e-12)
    tip = {name: np.array(data["point_displacements"]["tip"]) for name, data in runs.items()}
    np.testing.assert_allclose(tip["mass"], api.point_displacements["tip"], rtol=1e-9, atol=1e-12)
    scale = np.sqrt(runs["max"]["modal_mass"])[:, None]
    np.testing.assert_allclose(tip["max"] / scale, tip["mass"], rtol=1e-6, atol=1e-9 * np.abs(tip["mass"]).max())
    with pytest.raises(SystemExit):
        main(["modes", "--help"])
    assert "(default mass" in " ".join(capsys.readouterr().out.split())


def test_free_beam_modes_far_above_its_first_agree_with_fe_or_say_they_are_not_accurate(tmp_path, capsys):
    """A free beam's 60 modes raised LinAlgError: at its torsion and axial roots far above the
    first bending modes, the bending blocks of Ū_all are singular to 1/cosh βL < 1e-8, so
    the bordered system on the SVD's smallest directions was singular. Where it is, every
    near-null direction is taken and Newton's offsets pick the root's own. The first 15
    modes agree with FE's (MAC); the 20th (βL ≈ 30) is already 1.5e-5 to 1.1e-4 off.
    Above that the field along the beam is a difference of terms cosh βx apart that
    float64 cannot form (the 60th mode was 100 % off, without a word): the function's
    and the command's note names the first mode that is not accurate."""
    from random_models import to_toml

    from linmstmm.cli import main
    from linmstmm.compare import fe_mac

    model = single_beam_model()
    result = mode_shapes(model, 15)
    assert result.note == "" and result.mass_orthogonality_error < 1e-5
    _, mac = fe_mac(result, model)
    assert np.diag(mac).min() > 1 - 1e-6
    many = mode_shapes(model, 60)
    assert many.mass_orthogonality_error > 1e-4
    assert "are not accurate in float64" in many.note
    path = tmp_path / "beam.toml"
    path.write_text(to_toml(model))
    assert main(["modes", str(path), "--count", "60"]) == 0
    assert "are not accurate in float64" in capsys.readouterr().out


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_the_root_boundary_keeps_its_conditions_in_every_mode(engine):
    """A random tree rooted at a clamped spring end (``p3``): its three highest of twelve
    modes (650–1150 Hz) showed the root moving by up to 2.4 % (compiled) and 0.75 % (numpy)
    of the mode's largest point displacement, the carried root state's residual of the main transfer equation, and
    the twelfth mode's MAC against FE fell to 1 − 2.9e-4 (compiled) and 1 − 6.9e-6
    (numpy). The root's port now holds the root's own state: zero where the end is
    fixed. Reference: the FE route (Hermite beams, 128 elements per beam) on the same
    model, its eigenvectors at every point."""
    from random_models import random_model

    from linmstmm.fe import assemble, fe_modes

    model = random_model("tree", 29)
    modes = mode_shapes(model, 12, engine=engine)
    assert np.all(modes.point_displacements["p3"] == 0.0)
    fe = assemble(model, 128)
    lam, X, _ = fe_modes(fe, 12)
    full = fe.T @ X
    points = list(model.points)
    fe_shapes = np.stack([np.concatenate([full[fe.dof_index.point(p), k] for p in points])
                          for k in range(lam.size)])
    # the same modes in the same order (this mesh's own frequency error reaches 2.5e-5 at the twelfth)
    np.testing.assert_allclose(modes.omega, np.sqrt(lam), rtol=1e-4)
    assert np.diag(modes.mac(fe_shapes, points)).min() > 1 - 1e-6
