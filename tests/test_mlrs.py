"""The MLRS-style launcher (models/mlrs/) and its firing scenes (linmstmm.scenes).

As in the published MLRS study (docs/method.md): eight boundary ends and one
closed loop give Ū_all of order 60, and the first six natural frequencies lie
in 2-6 Hz. A scene only changes how the
same launcher is modelled (which tube is flexible), so the whole launcher's
mass, mass centre and inertia must not change from scene to scene.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from linmstmm.deduction import Deduction
from linmstmm.model import load_model
from linmstmm.scenes import (SceneMaker, beam_props, bundle_beside, cradle_props, loaded_tube, rigid_props,
                             salvo, scene_model, scene_sweep, scene_values, tube_axes)
from linmstmm.solve import natural_frequencies
from linmstmm.topology import build_topology

MODEL = Path(__file__).resolve().parents[1] / "models" / "mlrs" / "mlrs.toml"


@pytest.fixture(scope="module")
def model():
    return load_model(MODEL)


@pytest.fixture(scope="module")
def bundle(model):
    return bundle_beside(model)


@pytest.fixture(scope="module")
def mstmm(model):
    return natural_frequencies(model, count=10)


def whole(model):
    """Mass properties of the whole launcher moving rigidly."""
    parts = [rigid_props(r) for r in model.rigids] + [beam_props(b, model.points) for b in model.beams]
    return sum(parts[1:], parts[0])


def test_topology_is_the_studys(model):
    topology = build_topology(model)
    labels = sorted(b.label for b in topology.boundaries)
    assert labels == sorted(["breech free end", "muzzle"] + [f"ground{i}" for i in range(1, 7)])
    assert all(b.fixed.all() for b in topology.boundaries if b.label.startswith("ground"))
    assert len(topology.cuts) == 1
    assert Deduction(topology).order == 60


def test_about_twenty_tonnes(model):
    assert 19e3 < whole(model).mass < 21e3


def test_file_cradle_is_frame_plus_lumped_tubes(model, bundle):
    """The cradle in mlrs.toml is what the scene code builds for the base tube."""
    cradle = rigid_props(model.element("cradle"))
    built = cradle_props(model, bundle, bundle.base_tube)
    assert built.mass == pytest.approx(cradle.mass, rel=1e-6)
    np.testing.assert_allclose(built.com, cradle.com, atol=1e-6)
    np.testing.assert_allclose(built.inertia, cradle.inertia, atol=1e-6 * np.abs(cradle.inertia).max())


def _cradle_by_slots(model, bundle, tube, fired):
    """The cradle of scene ``tube`` summed slot by slot from the frame, with nothing shared."""
    axes = tube_axes(model, bundle)
    loaded, rocket = loaded_tube(model, bundle)
    total = bundle.frame(axes)
    for slot in bundle.slots:
        if slot != tube:
            lumped = loaded - rocket if slot in fired else loaded
            total = total + lumped.shifted(bundle.offset(slot, axes))
    return total


def test_scenes_sharing_their_sums_are_the_scenes_made_alone(model, bundle):
    """A SceneMaker kept over many scenes (in any order, any rockets fired) shares the
    cradle's sums over the slots: every value must be the one of the scene made alone,
    and its cradle the slot-by-slot sum, bit for bit."""
    rng = np.random.default_rng(3)
    maker = SceneMaker(model, bundle)
    shared = 0
    for _ in range(60):
        tube = int(rng.integers(1, 19))
        fired = frozenset(int(s) for s in rng.choice(np.arange(1, 19), int(rng.integers(0, 18)), replace=False)) - {tube}
        if rng.random() < 0.3:
            fired = salvo(tube)
        before = len(maker._sums)
        values = maker.values(tube, fired)
        shared += len(maker._sums) - before < len(bundle.slots) - 1
        assert values == scene_values(model, tube, fired, bundle)
        cradle, alone = maker.cradle(tube, fired), _cradle_by_slots(model, bundle, tube, fired)
        assert cradle.mass == alone.mass
        assert np.array_equal(cradle.com, alone.com) and np.array_equal(cradle.inertia, alone.inertia)
    assert shared  # some scenes took sums made for others


def test_a_scene_lumps_only_the_tubes_its_cradle_sums(model, bundle):
    """One scene asked of a new SceneMaker lumps the other tubes as that scene has them,
    loaded or fired, and no more (its values are checked bit for bit above)."""
    maker = SceneMaker(model, bundle)
    maker.values(7, {2, 3})
    assert sorted(maker._lumped) == sorted((slot, slot in {2, 3}) for slot in bundle.slots if slot != 7)


def test_smeared_rocket_leaves_steel(model, bundle):
    """The tube beams' density is steel plus the bundle's rocket smeared over them."""
    beams = [model.element(name) for name in ("tube_aft", "tube_fore")]
    length = sum(b.length for b in beams)
    assert length == pytest.approx(4.4, abs=1e-5)
    steel = beams[0].rho - bundle.rocket_mass / (beams[0].A * length)
    assert steel == pytest.approx(7850.0, rel=1e-5)


@pytest.mark.parametrize("tube", [1, 6, 8, 13, 18])
def test_scene_models_the_same_launcher(model, bundle, tube):
    """Same rigid-body mass properties as the base scene (the file's cradle is rounded)."""
    scene = scene_model(model, tube)
    assert Deduction(build_topology(scene)).order == 60
    for spring in scene.springs:
        a, b = (scene.points[p] for p in spring.ends)
        np.testing.assert_allclose(a, b, atol=1e-9)
    for beam in scene.beams:
        a, b = (scene.points[p] for p in beam.ends)
        assert np.linalg.norm(b - a) == pytest.approx(beam.length, abs=1e-9)
    reference, moved = whole(scene_model(model, bundle.base_tube)), whole(scene)
    assert moved.mass == pytest.approx(reference.mass, rel=1e-12)
    np.testing.assert_allclose(moved.com, reference.com, atol=1e-9)
    np.testing.assert_allclose(moved.inertia, reference.inertia, atol=1e-9 * reference.inertia.max())


def test_scene_moves_the_tube_to_its_slot(model, bundle):
    """Tube 18 (bottom right) sits two rows down and five columns right of tube 1."""
    scene = scene_model(model, 18)
    shift = scene.points["muzzle"] - model.points["muzzle"]
    along = model.element("tube_aft").axes[0]
    assert shift @ along == pytest.approx(0.0, abs=1e-12)
    assert shift[1] == pytest.approx(-5 * bundle.column_spacing)
    assert np.linalg.norm(shift) == pytest.approx(np.hypot(5 * 0.30, 2 * 0.30))
    assert scene.points["trunnion_cradle"] is model.points["trunnion_cradle"]


def test_fired_rockets_lighten_the_cradle(model, bundle):
    scene = scene_model(model, 5, salvo(5))
    assert whole(model).mass - whole(scene).mass == pytest.approx(4 * bundle.rocket_mass)
    with pytest.raises(ValueError, match="fires in this scene"):
        scene_model(model, 5, {5})
    with pytest.raises(ValueError, match="not slots"):
        scene_model(model, 5, {19})
    with pytest.raises(ValueError, match="not a slot"):
        scene_model(model, 0)


def test_first_six_in_the_studys_band(mstmm):
    assert mstmm.ubar_order == 60
    assert mstmm.rigid_body_modes == 0
    assert np.all((mstmm.frequencies_hz[:6] > 2.0) & (mstmm.frequencies_hz[:6] < 6.0))


def test_agrees_with_finite_elements(model, mstmm):
    from linmstmm.fe import fe_frequencies

    reference = fe_frequencies(model, count=10).frequencies_hz
    np.testing.assert_allclose(mstmm.frequencies_hz, reference, rtol=1e-7)


def test_thirty_modes_with_their_close_pairs_from_the_cheap_repairs(model, monkeypatch):
    """The launcher's left/right pairs (19.40/19.46, 21.86/21.88, 26.87/26.89 Hz: 0.08-0.3 %
    apart) share a scan step with no sign change between them. The pencil at a found
    neighbour points at them (the deferred members), so the fast path closes without
    the deflated-count recovery, and agrees with the FE route."""
    from linmstmm.fe import fe_frequencies
    from linmstmm.roots import RootFinder

    monkeypatch.setattr(RootFinder, "_recovered", lambda *args: pytest.fail("needed the deflated-count recovery"))
    found = natural_frequencies(model, count=30).frequencies_hz
    np.testing.assert_allclose(found, fe_frequencies(model, count=30).frequencies_hz, rtol=1e-7)


@pytest.mark.parametrize("omega", [3000.0, 8000.0])
def test_det_stays_accurate_where_the_tube_between_its_supports_grows(model, omega):
    """The loop cradle - supports - tube is cut at the tube's front support, so the
    cut's unknowns ride along the tube until both arcs meet at the cradle. They are
    orthonormalised with every block that holds them: det Ū_all agrees with the
    mpmath determinant at 40 digits to 1e-10 (left alone they grew 1e16 and det was
    off by 2e-7 at 8000 rad/s)."""
    import mpmath

    from linmstmm.precision import mp_determinant

    deduction = Deduction(build_topology(model))
    _, log_abs = deduction.log_det(np.array([omega]))
    with mpmath.workdps(40):
        reference = float(mpmath.log(abs(mp_determinant(deduction, mpmath.mpf(omega)))))
    assert abs(log_abs[0] - reference) < 1e-10


def test_a_root_newton_cannot_reach_is_isolated_from_its_sign_change(model):
    """682.27 Hz, 0.25 % below its pair: the orthonormalised Ū_all is not smooth enough
    there for Newton on its pencil, so the count bisection (RootFinder._isolate) takes
    it from the sign change by regula falsi on det (it raised "cannot count" before);
    it agrees with the FE route."""
    from linmstmm.fe import fe_frequencies
    from linmstmm.solve import frequency_finder

    _, finder, _ = frequency_finder(model)
    reference = fe_frequencies(model, count=76).frequencies_hz
    target = 2 * np.pi * reference[np.argmin(np.abs(reference - 682.27))]
    found = finder._isolate(target * (1 - 1e-4), target * (1 + 1e-4), 1, [])
    np.testing.assert_allclose(found, [target], rtol=1e-9)


def test_sweep_over_a_salvo(model, mstmm):
    """Scene 1 is the model file (whose cradle is rounded to 7 digits); by tube 18,
    17 rockets are gone and every mode is higher."""
    (_, first), (_, last) = scene_sweep(model, count=6, tubes=[1, 18], fired=salvo)
    np.testing.assert_allclose(first, mstmm.frequencies_hz[:6], rtol=1e-6)
    assert np.all(last > 1.05 * first)


@pytest.mark.parametrize("fired", [None, salvo], ids=["all other tubes loaded", "salvo"])
def test_every_scene_agrees_with_finite_elements(model, fired):
    """The first ten frequencies of all 18 scenes agree with the FE route to 1e-7."""
    from linmstmm.fe import fe_frequencies

    sweep = scene_sweep(model, count=10, fired=fired)
    assert [tube for tube, _ in sweep] == list(range(1, 19))
    for tube, frequencies in sweep:
        scene = scene_model(model, tube, fired(tube) if fired else frozenset())
        reference = fe_frequencies(scene, count=10).frequencies_hz
        np.testing.assert_allclose(frequencies, reference, rtol=1e-7, err_msg=f"tube {tube}")


def test_warm_started_sweep_equals_cold_sweep():
    """Scenes started from the previous scene's roots give the cold search's roots."""
    tubes = [1, 7, 18]
    warm = scene_sweep(MODEL, count=6, tubes=tubes, warm_start=True)
    cold = scene_sweep(MODEL, count=6, tubes=tubes, warm_start=False)
    for (_, w), (_, c) in zip(warm, cold):
        np.testing.assert_allclose(w, c, rtol=1e-10)


def _scene_file(values: dict, folder) -> Path:
    """mlrs.toml with a scene's values (key -> value, linmstmm.parameters keys) written into
    its TOML document, without linmstmm: points, rigid masses, mass centres, inertia tensors."""
    import re
    import tomllib

    from test_sweep import dump_toml

    document = tomllib.loads(MODEL.read_text())
    for key, value in values.items():
        head, *index = re.split(r"\[", key)
        index = [int(i.rstrip("]")) for i in index]
        section, rest = head.split(".", 1)
        if section == "points":
            document["points"][rest][index[0]] = value
            continue
        name, field = rest.rsplit(".", 1)
        table = next(t for t in document[section] if t["name"] == name)
        if not index:
            table[field] = value
        elif len(index) == 1:
            table[field][index[0]] = value
        else:
            table[field][index[0]][index[1]] = table[field][index[1]][index[0]] = value
    out = Path(folder) / f"scene_{abs(hash(tuple(values.items())))}.toml"
    out.write_text(dump_toml(document))
    return out


def test_scenes_through_the_sweep_are_freqs_on_the_edited_files(model, bundle, tmp_path):
    """Two salvo scenes as steps of the sweep engine (the second warm-started from the
    first, tracked by MAC, in this process and in two processes) give what
    natural_frequencies gives, from a cold start, on the model file with each scene's values
    written into it; to rounding (1e-10, as warm against cold above), and bitwise the same
    whatever runs the steps."""
    from linmstmm.scenes import scene_study, scene_values

    tubes = [7, 12]
    serial = scene_study(model, count=6, tubes=tubes, fired=salvo, bundle=bundle, engine="numpy")
    parallel = scene_study(model, count=6, tubes=tubes, fired=salvo, bundle=bundle, engine="numpy", workers=2)
    assert serial.warm_start and serial.engine == "numpy"
    np.testing.assert_array_equal(parallel.frequencies_hz_by_rank, serial.frequencies_hz_by_rank)
    np.testing.assert_array_equal(parallel.order, serial.order)
    for tube, row in zip(tubes, serial.frequencies_hz_by_rank):
        edited = load_model(_scene_file(scene_values(model, tube, salvo(tube), bundle), tmp_path))
        reference = natural_frequencies(edited, count=6, engine="numpy").frequencies_hz
        np.testing.assert_allclose(row, reference, rtol=1e-10, err_msg=f"tube {tube}")
    assert np.all(serial.tracking_mac[1] > 0.9)  # each column keeps its shape from scene 7 to 12


def test_a_salvo_sweep_starts_from_predictions_or_a_trend_once_its_scenes_move_farther_than_they_err(
        model, bundle, monkeypatch):
    """In the salvo the frequencies move 1-1.4 % a scene, the coarse predictions are 1e-6
    off: the second scene starts from the first's roots (no move seen yet), the third
    from its own predictions (no extrapolation measured yet), the fourth from the third's
    roots extrapolated along their last move (the same extrapolation missed the third's
    by about 5e-4, within √1e-6); with every other tube loaded (moves of 40 ppm) every
    scene after the first starts from the previous one's roots. Each scene's roots are
    natural_frequencies' from a cold start, to rounding (1e-10, as warm against cold above)."""
    import linmstmm.solve
    from linmstmm.scenes import scene_study

    started = []
    solve = linmstmm.solve.natural_frequencies

    def recorded(*args, guess_hz=None, **options):
        started.append(guess_hz is not None)
        return solve(*args, guess_hz=guess_hz, **options)

    monkeypatch.setattr(linmstmm.solve, "natural_frequencies", recorded)
    tubes = [3, 4, 5, 6]
    scene_study(model, count=6, tubes=tubes, bundle=bundle, engine="compiled", track_modes=False)
    assert started == [False, True, True, True]
    started.clear()
    fired = scene_study(model, count=6, tubes=tubes, fired=salvo, bundle=bundle, engine="compiled",
                        track_modes=False)
    assert started == [False, True, False, True]
    for tube, row in zip(tubes, fired.frequencies_hz_by_rank):
        cold = solve(scene_model(model, tube, salvo(tube), bundle), count=6, engine="compiled").frequencies_hz
        np.testing.assert_allclose(row, cold, rtol=1e-10, err_msg=f"tube {tube}")
