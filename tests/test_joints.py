"""Joints: springs with released directions (pin, universal, ball, slider).

A released direction transmits no force and leaves the two ends free to move
apart there: in the transfer matrix method its jump is an unknown of Ū_all and
its zero force a row; in the FE route it has no stiffness. Each model here is
checked against a closed form derived in its test, or against the FE route on
the same model, and its zero-frequency count (rigid-body and mechanism modes,
from the model's kinematics) against the FE route's, in other units too.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from builders import fixed, make_beam, make_rigid, make_spring
from random_models import random_model
from test_rigid_body_modes import in_other_units

from linmstmm.cli import main
from linmstmm.fe import fe_frequencies
from linmstmm.model import Model, ModelError, load_model
from linmstmm.modes import mode_shapes
from linmstmm.coarse_prediction import coarse_predictions
from linmstmm.response import frf
from linmstmm.rigid_motion import rigid_body_mode_count
from linmstmm.solve import natural_frequencies
from linmstmm.structure import describe
from linmstmm.topology import build_topology

INF = np.inf
#: A pin about the spring's local z: rigid in the other five directions.
PIN = [INF] * 5 + [0.0]
#: Steel beams of the default section of the builders (A 1e-3 m², I 2e-7 m⁴, J 4e-7 m⁴).
E, RHO, I, AREA = 2.1e11, 7850.0, 2e-7, 1e-3


def points(**positions) -> dict:
    return {name: np.asarray(x, float) for name, x in positions.items()}


def slender_link(name, a, b, mass, start, length) -> object:
    """A rigid uniform rod along x from ``start`` (m), ports a and b at its ends."""
    return make_rigid(name, [a, b], mass, [start + length / 2, 0, 0],
                      [0.0, mass * length ** 2 / 12, mass * length ** 2 / 12])


def hinged_chain(mass=3.0, length=0.8, kt=500.0) -> Model:
    """Two rods in a row along x, the first pinned to the ground, the second to the
    first's tip; each pin (rz released) in parallel with a torsion spring kt (every
    direction but rz released): two loops of two springs between the same points."""
    L = length
    pts = points(g=[0, 0, 0], a1=[0, 0, 0], b1=[L, 0, 0], a2=[L, 0, 0], b2=[2 * L, 0, 0])
    springs = []
    for i, (a, b) in enumerate((("g", "a1"), ("b1", "a2")), 1):
        springs.append(make_spring(f"pin{i}", a, b, PIN, release=["rz"]))
        springs.append(make_spring(f"torsion{i}", a, b, [0.0] * 5 + [kt], release=["x", "y", "z", "rx", "ry"]))
    return Model("hinged chain", pts, rigids=(slender_link("link1", "a1", "b1", mass, 0.0, L),
                                             slender_link("link2", "a2", "b2", mass, L, L)),
                 springs=tuple(springs), boundary={"g": fixed()})


def test_hinged_chain_against_its_closed_form():
    """Two rods (mass m, length L) hinged in a row, a torsion spring kt at each pin.

    With absolute angles θ1, θ2 about z (small, no gravity), the second rod's
    centre moves by L θ1 + L θ2 / 2, so
    T = ½ (m L²/3) θ1'² + ½ m (L θ1' + L θ2'/2)² + ½ (m L²/12) θ2'²,
    V = ½ kt θ1² + ½ kt (θ2 − θ1)²:
    M = m L² [[4/3, 1/2], [1/2, 1/3]], K = kt [[2, −1], [−1, 1]].
    det(K − λ M) = kt² − 3 kt λ m L² + (7/36) (λ m L²)² = 0, so
    ω² = (54 ∓ 6 √74) / 7 · kt / (m L²). Every other motion is held by the pins.
    """
    mass, length, kt = 3.0, 0.8, 500.0
    model = hinged_chain(mass, length, kt)
    exact = np.sqrt(np.array([54 - 6 * np.sqrt(74), 54 + 6 * np.sqrt(74)]) / 7 * kt / (mass * length ** 2))
    result = natural_frequencies(model, count=4)
    assert result.rigid_body_modes == 0 == rigid_body_mode_count(model)
    np.testing.assert_allclose(result.frequencies_hz, exact / (2 * np.pi), rtol=1e-12)


def pinned_bars(mass=2.0, length=1.5, k=1e4, k0=None) -> Model:
    """Two rods pinned to the ground at their outer ends (pins about z), tips meeting
    at x = L and joined there by a spring k in y and z, free in x and in rotation (a
    ball joint on a slider); with ``k0``, the first tip also springs to the ground."""
    L = length
    pts = points(g1=[0, 0, 0], o1=[0, 0, 0], p1=[L, 0, 0], p2=[L, 0, 0], o2=[2 * L, 0, 0], g2=[2 * L, 0, 0])
    link = [0.0, k, k, 0.0, 0.0, 0.0]
    springs = [make_spring("pin1", "g1", "o1", PIN, release=["rz"]),
               make_spring("pin2", "g2", "o2", PIN, release=["rz"]),
               make_spring("link", "p1", "p2", link, release=["x", "rx", "ry", "rz"])]
    boundary = {"g1": fixed(), "g2": fixed()}
    if k0 is not None:
        pts["t1"] = pts["p1"].copy()
        springs.append(make_spring("ground", "t1", "p1", [0.0, k0, k0, 0.0, 0.0, 0.0],
                                   release=["x", "rx", "ry", "rz"]))
        boundary["t1"] = fixed()
    bar2 = make_rigid("bar2", ["o2", "p2"], mass, [1.5 * L, 0, 0], [0.0, mass * L ** 2 / 12, mass * L ** 2 / 12])
    return Model("pinned bars", pts, rigids=(slender_link("bar1", "o1", "p1", mass, 0.0, L), bar2),
                 springs=tuple(springs), boundary=boundary)


def test_pinned_bars_mechanism_and_elastic_mode():
    """Tip deflections y1 = L θ1, y2 (small rotations about the pins): each rod's
    inertia about its pin is m L²/3, i.e. m/3 at its tip; V = ½ k (y1 − y2)² + ½ k0 y1².
    Without k0: one mechanism (y1 = y2, the rods turn together) and ω² = 6 k / m.
    With k0: M = m/3 I, K = [[k0 + k, −k], [−k, k]], ω² = (3/m)(k0/2 + k ∓ √(k0²/4 + k²)).
    """
    mass, k, k0 = 2.0, 1e4, 3e3
    free = natural_frequencies(pinned_bars(mass, k=k), count=3)
    assert free.rigid_body_modes == 1
    np.testing.assert_allclose(free.frequencies_hz, [np.sqrt(6 * k / mass) / (2 * np.pi)], rtol=1e-12)
    held = natural_frequencies(pinned_bars(mass, k=k, k0=k0), count=3)
    roots = k0 / 2 + k + np.array([-1.0, 1.0]) * np.sqrt(k0 ** 2 / 4 + k ** 2)
    assert held.rigid_body_modes == 0
    np.testing.assert_allclose(held.frequencies_hz, np.sqrt(3 / mass * roots) / (2 * np.pi), rtol=1e-12)


def test_mode_shapes_show_the_joints_relative_motion():
    """In the mechanism mode the rods turn opposite ways (y1 = L θ1 = y2 = −L θ2): the
    tips move alike in y and the link's rotation jumps by −2 θ1; in the elastic mode the
    tips move apart. Mode shapes of both are orthogonal and their energies balance."""
    modes = mode_shapes(pinned_bars(), count=2)
    assert modes.rigid_body_modes == 1
    tip1, tip2 = modes.point_displacements["p1"], modes.point_displacements["p2"]
    mechanism, elastic = 0, 1
    np.testing.assert_allclose(tip2[mechanism, 1], tip1[mechanism, 1], rtol=1e-10)
    np.testing.assert_allclose(tip2[mechanism, 5], -tip1[mechanism, 5], rtol=1e-10)
    np.testing.assert_allclose(tip1[mechanism, 1], 1.5 * tip1[mechanism, 5], rtol=1e-10)
    np.testing.assert_allclose(tip2[elastic, 1], -tip1[elastic, 1], rtol=1e-10)
    assert modes.mass_orthogonality_error < 1e-12
    assert modes.stiffness_orthogonality_error < 1e-12
    assert modes.energy_error < 1e-12


def test_receptance_at_zero_frequency_is_the_flexibility():
    """The held pinned bars have two massive degrees of freedom and two modes, so the
    modal sum of the receptance is complete: at 0 Hz it is K⁻¹ in tip coordinates,
    K = [[k0 + k, −k], [−k, k]] (a unit force at tip 2 in y)."""
    k, k0 = 1e4, 3e3
    modes = mode_shapes(pinned_bars(k=k, k0=k0), count=2)
    result = frf(modes, "p2", [0, 1, 0, 0, 0, 0], [0.0], points=["p1", "p2"])
    flexibility = np.linalg.inv([[k0 + k, -k], [-k, k]])
    np.testing.assert_allclose(result.receptance[0, :, 1].real, flexibility[:, 1], rtol=1e-10)


def four_bar() -> Model:
    """A planar four-bar linkage of steel beams (crank, coupler, rocker) in the x-y
    plane, pinned about z to each other and to the ground at A and D."""
    corners = {"A": [0, 0, 0], "B": [0.3, 0.4, 0], "C": [1.2, 0.6, 0], "D": [1.0, 0, 0]}
    pts = points(**{name + side: x for name, x in corners.items() for side in "12"})
    beams = (make_beam("crank", "A2", "B1", pts), make_beam("coupler", "B2", "C1", pts),
             make_beam("rocker", "C2", "D1", pts))
    springs = tuple(make_spring(f"pin{c}", c + "1", c + "2", PIN, release=["rz"]) for c in "ABCD")
    return Model("four-bar", pts, beams=beams, springs=springs, boundary={"A1": fixed(), "D2": fixed()})


def test_four_bar_linkage_has_one_mechanism_and_the_fe_routes_frequencies():
    model = four_bar()
    result = natural_frequencies(model, count=6)
    check = fe_frequencies(model, count=6)
    assert result.rigid_body_modes == 1 == check.rigid_body_modes == rigid_body_mode_count(model)
    np.testing.assert_allclose(result.frequencies_hz, check.frequencies_hz, rtol=1e-9)


@pytest.mark.parametrize("build, mechanisms", [(four_bar, 1), (lambda: beam_on_joint(["rx", "ry", "rz"]), 3)],
                         ids=["four-bar linkage", "beam on a ball joint"])
def test_joints_forty_modes_up_agree_with_the_fe_route(build, mechanisms):
    """High up the spectrum (40 modes, up to where the beams bend in many half-waves) the
    mechanisms stay zero-frequency modes and no elastic frequency is lost or invented."""
    model = build()
    result, check = natural_frequencies(model, count=40), fe_frequencies(model, count=40)
    assert result.rigid_body_modes == mechanisms == check.rigid_body_modes
    assert result.frequencies_hz.size == 40 == check.frequencies_hz.size
    np.testing.assert_allclose(result.frequencies_hz, check.frequencies_hz,
                               rtol=max(1e-9, 3 * float(np.nanmax(check.error_estimate))))


def beam_on_joint(release, length=2.0) -> Model:
    """A steel beam along x from a joint to the ground at its start; free far end."""
    pts = points(g=[0, 0, 0], a=[0, 0, 0], b=[length, 0, 0])
    k = [0.0 if c in release else INF for c in ("x", "y", "z", "rx", "ry", "rz")]
    return Model("beam on a joint", pts, beams=(make_beam("beam", "a", "b", pts),),
                 springs=(make_spring("joint", "g", "a", k, release=release),), boundary={"g": fixed()})


def test_beam_on_a_ball_joint():
    """Three mechanism modes (the beam turns about the ball, its spin has inertia ρ Ip L);
    bending is pinned-free in both planes, tan βL = tanh βL: βL = 3.926602312, 7.068582745
    (each twice, Iy = Iz), ω = (βL)² √(E I / (ρ A L⁴)), below axial and torsion."""
    length = 2.0
    model = beam_on_joint(["rx", "ry", "rz"], length)
    result = natural_frequencies(model, count=4)
    check = fe_frequencies(model, count=4)
    assert result.rigid_body_modes == 3 == check.rigid_body_modes
    beta = np.repeat([3.926602312, 7.068582745], 2)
    exact = beta ** 2 * np.sqrt(E * I / (RHO * AREA * length ** 4)) / (2 * np.pi)
    np.testing.assert_allclose(result.frequencies_hz, exact, rtol=1e-9)
    np.testing.assert_allclose(result.frequencies_hz, check.frequencies_hz, rtol=1e-9)


def sliding_carts(direction=(1.0, 1.0, 0.0), m1=2.0, m2=5.0, k=800.0) -> Model:
    """Cart 1 on a slider to the ground along ``direction`` (every other direction
    rigid), cart 2 joined to it by a spring k along the same axis (rigid otherwise)."""
    x = np.asarray(direction, float) / np.linalg.norm(direction)
    y = np.cross([0.0, 0.0, 1.0], x)
    axes = np.array([x, y / np.linalg.norm(y), [0.0, 0.0, 1.0]])
    pts = points(g=[0, 0, 0], a=[0, 0, 0], b=[0, 0, 0], c=[0, 0, 0])
    bodies = (make_rigid("cart1", ["a", "b"], m1, [0, 0, 0], [0.1, 0.1, 0.1]),
              make_rigid("cart2", ["c"], m2, [0, 0, 0], [0.2, 0.2, 0.2]))
    springs = (make_spring("slider", "g", "a", [0.0] + [INF] * 5, axes, release=["x"]),
               make_spring("spring", "b", "c", [k] + [INF] * 5, axes))
    return Model("sliding carts", pts, rigids=bodies, springs=springs, boundary={"g": fixed()})


def test_slider_against_its_closed_form():
    """Both carts slide together (one mechanism mode) or against each other:
    ω² = k (1/m1 + 1/m2); the slider's axis is skew to the inertial axes."""
    m1, m2, k = 2.0, 5.0, 800.0
    model = sliding_carts(m1=m1, m2=m2, k=k)
    result = natural_frequencies(model, count=2)
    assert result.rigid_body_modes == 1 == fe_frequencies(model, count=1).rigid_body_modes
    np.testing.assert_allclose(result.frequencies_hz, [np.sqrt(k * (1 / m1 + 1 / m2)) / (2 * np.pi)], rtol=1e-12)


COUNTED = {"four-bar": (four_bar, 1), "ball": (lambda: beam_on_joint(["rx", "ry", "rz"]), 3),
           "universal": (lambda: beam_on_joint(["ry", "rz"]), 2), "pin": (lambda: beam_on_joint(["rz"]), 1),
           "slider": (lambda: beam_on_joint(["x"]), 1), "bars": (pinned_bars, 1),
           "carts": (sliding_carts, 1), "chain": (hinged_chain, 0)}


@pytest.mark.parametrize("length, mass, time", [(1.0, 1.0, 1.0), (1e-3, 1.0, 1.0), (1e-3, 1e3, 1.0),
                                                (1e-3, 1e-9, 1e-3), (0.5, 0.125, 0.5)])
@pytest.mark.parametrize("name", COUNTED)
def test_mechanism_counts_agree_with_the_fe_route_in_any_units(name, length, mass, time):
    """mm-kg-s, mm-t-s and the like: the same model in other consistent units has the
    same zero-frequency count, from the kinematics and in the FE route, and its
    frequencies in the new time unit (with 1e-3 m, 1e-9 kg, 1e-3 s: read as SI, a model
    1000 times larger, whose frequencies are 1000 times lower)."""
    build, expected = COUNTED[name]
    model = in_other_units(build(), length, mass, time)
    assert rigid_body_mode_count(model) == expected
    assert fe_frequencies(model, count=1, elements_per_beam=2).rigid_body_modes == expected
    if (length, mass, time) != (1.0, 1.0, 1.0):
        original, converted = natural_frequencies(build(), count=2), natural_frequencies(model, count=2)
        assert converted.rigid_body_modes == expected
        np.testing.assert_allclose(converted.frequencies_hz / time, original.frequencies_hz, rtol=1e-9)


def test_the_compiled_engine_gives_the_same_frequencies():
    """The compiled program carries the joints' rows and jumps as the numpy carry does."""
    for model in (four_bar(), pinned_bars(k0=3e3), hinged_chain()):
        np.testing.assert_allclose(natural_frequencies(model, count=3, engine="compiled").frequencies_hz,
                                   natural_frequencies(model, count=3, engine="numpy").frequencies_hz, rtol=1e-12)


def test_the_compiled_program_knows_the_kinds_of_the_rows_the_numpy_carry_finds():
    """What each row of Ū_all is (displacement, rotation, moment, force: the scales of the
    release in the model's own units) from the compiled program's rows, as the numpy
    carry labels them: joints' force and moment rows, geometric rows, bundled models."""
    from builders import BUNDLED_MODELS

    from linmstmm.deduction import Deduction
    from linmstmm.program import compile_program

    models = [four_bar(), pinned_bars(k0=3e3), hinged_chain(), beam_on_joint(["rx", "ry", "rz"]), sliding_carts()]
    for model in models + [load_model(path) for path in BUNDLED_MODELS]:
        carried = Deduction(build_topology(model)).kinds()[0]
        adopted = Deduction(build_topology(model))
        adopted.adopt_row_kinds(compile_program(adopted).row_kinds)
        np.testing.assert_array_equal(adopted.kinds()[0], carried, err_msg=model.name)


SPRING = """name = "m"
[points]
g = [0, 0, 0]
a = [0, 0, 0]
[[rigid]]
name = "body"
ports = ["a"]
mass = 1.0
com = [0, 0, 0]
inertia = [1, 1, 1]
[[spring]]
name = "joint"
ends = ["g", "a"]
{spring}
[boundary]
g = "fixed"
"""


@pytest.mark.parametrize("spring, key, message", [
    ('k = [inf, inf, inf, inf, inf, 0]', "k", "k[5] must be > 0, got 0; to leave direction 'rz' free"),
    ('k = [inf, inf, inf, inf, inf, 5]\nrelease = ["rz"]', "k", "k[5] = 5 but 'rz' is released"),
    ('k = [inf, inf, inf, inf, inf, inf]\nrelease = ["rz"]', "k", "k[5] = inf but 'rz' is released"),
    ('k = [inf, inf, inf, inf, inf, 0]\nrelease = ["rz", "rz"]', "release", "component 'rz' is listed twice"),
    ('k = [inf, inf, inf, inf, inf, 0]\nrelease = ["theta"]', "release", "release[0] = string 'theta' is not one of"),
    ('k = [inf, inf, inf, inf, inf, 0]\nrelease = "rz"', "release", "must be a list drawn from"),
    ('k = [0, 0, 0, 0, 0, 0]\nrelease = ["x", "y", "z", "rx", "ry", "rz"]', "release", "all six directions"),
    ('k = [inf, inf, inf, inf, inf, -3]\nrelease = ["x"]', "k", "k[0] = inf but 'x' is released"),
    ('k = [inf, inf, inf, inf, inf, -3]', "k", "k[5] must be > 0, got -3"),
])
def test_ambiguous_or_contradictory_releases_are_refused(tmp_path, capsys, spring, key, message):
    path = tmp_path / "joint.toml"
    path.write_text(SPRING.format(spring=spring))
    with pytest.raises(ModelError) as error:
        load_model(path)
    assert (error.value.element, error.value.key) == ("spring 'joint'", key)
    assert message in error.value.message
    assert main(["freqs", str(path)]) == 2
    assert "Traceback" not in capsys.readouterr().err


def test_a_released_model_built_in_code_is_checked_like_a_file():
    with pytest.raises(ModelError, match=r"spring 'pin1': key 'k': k\[5\] = 7 but 'rz' is released"):
        Model("bad", {"g": np.zeros(3), "a": np.zeros(3)},
              rigids=(make_rigid("m", ["a"], 1.0, [0, 0, 0], [1, 1, 1]),),
              springs=(make_spring("pin1", "g", "a", [INF] * 5 + [7.0], release=["rz"]),), boundary={"g": fixed()})


def test_check_report_shows_the_jumps_and_the_zero_force_rows():
    """The ball joint adds three unknowns (its jumps) and three rows (no moment), so
    Ū_all is of order 12 + 3 with the two boundary ends' 6 + 6 unknowns."""
    report = describe(build_topology(beam_on_joint(["rx", "ry", "rz"])))
    assert report.ubar_order == 15
    assert [(joint.name, joint.released) for joint in report.joints] == [("joint", ("rx", "ry", "rz"))]
    assert report.block_rows == ("main", "joint free") and "Δ[joint]" in report.block_columns
    text = report.to_text()
    assert "(12 main rows + 6 x 0 geometric rows + 3 joint rows)" in text
    assert "Δ[joint]: Δrx Δry Δrz" in text


def test_a_joint_within_one_rigid_assembly_holds_nothing():
    """Two free bodies welded at s, a joint between their ports p and q (which
    coincide to 1e-11 m, within the loader's tolerance): the joint's ends move alike
    in every rigid motion of the assembly, so it holds none of its six rigid-body
    modes, in the kinematics as in the FE route (its rows are rounding, not rank)."""
    pts = points(p=[0, 0, 0], s=[1.0, 0, 0], q=[0, 1e-11, 0])
    model = Model("welded", pts, rigids=(make_rigid("one", ["p", "s"], 2.0, [0.5, 0.1, 0], [0.1, 0.2, 0.3]),
                                         make_rigid("two", ["s", "q"], 3.0, [0.5, -0.1, 0], [0.2, 0.2, 0.3])),
                  springs=(make_spring("joint", "p", "q", [1e4, 1e4, 1e4, 0.0, 0.0, 1e3], release=["rx", "ry"]),))
    assert rigid_body_mode_count(model) == 6 == fe_frequencies(model, count=1).rigid_body_modes


def test_a_massless_point_free_to_turn_between_two_joints():
    """The beam on a ball joint again, with a massless point between the ball and the
    beam and a pin (rz released, elastic in rx and ry) between that point and the
    beam: the point turns about z freely and carries no mass, a motion with neither
    stiffness nor mass that is no mode (and that the coarse prediction must remove
    before its eigenproblem). The frequencies stay the pinned-free beam's."""
    length = 2.0
    pts = points(g=[0, 0, 0], m=[0, 0, 0], a=[0, 0, 0], b=[length, 0, 0])
    model = Model("beam behind a ball and a pin", pts, beams=(make_beam("beam", "a", "b", pts),),
                  springs=(make_spring("ball", "g", "m", [INF] * 3 + [0.0] * 3, release=["rx", "ry", "rz"]),
                           make_spring("pin", "m", "a", [INF] * 3 + [3e4, 3e4, 0.0], release=["rz"])),
                  boundary={"g": fixed()})
    result = natural_frequencies(model, count=2)
    assert result.rigid_body_modes == 3 == fe_frequencies(model, count=1).rigid_body_modes
    exact = 3.926602312 ** 2 * np.sqrt(E * I / (RHO * AREA * length ** 4)) / (2 * np.pi)
    np.testing.assert_allclose(result.frequencies_hz, [exact, exact], rtol=1e-9)
    coarse = coarse_predictions(model, 2) / (2 * np.pi)  # two Hermite elements: within 1 %
    np.testing.assert_allclose(coarse, [exact, exact], rtol=1e-2)


def test_a_stiff_loop_beside_a_joint_is_no_indeterminate_unknown():
    """A random grounded model with loops (two beams between the same two points) and
    two of its springs made joints: Ū_all's smallest singular value is 8e-10 of the
    largest at every probe (the loop's axial compliance), not the rounding-level zero
    of a redundant constraint; taking it for one moved the frequencies by 2.7e-4."""
    model = random_model("loops", 10)
    releases = {"spring0": ["x", "z", "rz"], "spring3": ["z", "rx"]}
    springs = tuple(dataclasses.replace(s, k=np.where(mask, 0.0, s.k), release=mask) if mask.any() else s
                    for s in model.springs
                    for mask in [np.isin(["x", "y", "z", "rx", "ry", "rz"], releases.get(s.name, []))])
    model = dataclasses.replace(model, springs=springs)
    result, check = natural_frequencies(model, count=6), fe_frequencies(model, count=6)
    assert result.indeterminate_released == 0
    np.testing.assert_allclose(result.frequencies_hz, check.frequencies_hz, rtol=1e-9)


def with_random_joints(model: Model, rng: np.random.Generator) -> Model:
    """``model`` with one to three random directions released in seven springs of ten."""
    springs = []
    for spring in model.springs:
        mask = np.zeros(6, bool)
        if rng.random() < 0.7:
            mask[rng.choice(6, rng.integers(1, 4), replace=False)] = True
        springs.append(dataclasses.replace(spring, k=np.where(mask, 0.0, spring.k), release=mask)
                       if mask.any() else spring)
    return dataclasses.replace(model, springs=tuple(springs))


@pytest.mark.parametrize("kind", ["tree", "floating_tree", "loops", "floating_loops", "ring"])
@pytest.mark.parametrize("number", [0, 1, 2])
def test_random_models_with_joints_agree_with_the_fe_route(kind, number):
    """Random models (rigid bodies, springs, beams, junctions, loops) with random
    joints: the same zero-frequency count and the same lowest six frequencies."""
    model = with_random_joints(random_model(kind, number), np.random.default_rng(1000 + number))
    result, check = natural_frequencies(model, count=6), fe_frequencies(model, count=6)
    assert result.rigid_body_modes == check.rigid_body_modes == rigid_body_mode_count(model)
    np.testing.assert_allclose(result.frequencies_hz, check.frequencies_hz, rtol=1e-9)
