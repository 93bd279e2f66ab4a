"""Rigid-body (zero-frequency) mode counts from the model's kinematics, against the FE route.

The FE route finds its rigid motions from the assembled stiffness's kinematics
on a meshed model; the transfer-matrix route used to read them off small
singular values of Ū_all(0) at a fixed threshold, which miscounted stars of
stiff, heavy beams (1 for 3 and 4 arms, 6 for 8). Each count here must match
the FE route's and must not change when the same model is written in other
consistent units or scaled in size.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from builders import fixed, make_beam, make_rigid, make_spring
from linmstmm.fe import fe_frequencies
from linmstmm.model import Model
from linmstmm.modes import mode_shapes
from linmstmm.rigid_motion import rigid_body_mode_count
from linmstmm.solve import natural_frequencies

STEEL = dict(E=200e9, G=77e9, rho=8000.0)


def pinned_star(arms: int, length: float = 5.0, width: float = 0.125, height: float = 0.125) -> Model:
    """Equal arms from a rigid centre, evenly spread in the x-y plane, pinned at their far ends."""
    area = width * height
    points = {"centre": np.zeros(3)}
    for i in range(arms):
        angle = 2 * np.pi * i / arms
        points[f"end{i}"] = length * np.array([np.cos(angle), np.sin(angle), 0.0])
    beams = tuple(make_beam(f"arm{i}", "centre", f"end{i}", points, A=area, Iy=width * height ** 3 / 12,
                            Iz=height * width ** 3 / 12, J=0.1406 * width * height ** 3 if width >= height
                            else 0.1406 * height * width ** 3, material=STEEL)
                  for i in range(arms))
    return Model(f"star of {arms}", points, beams=beams,
                 boundary={f"end{i}": fixed("x", "y", "z") for i in range(arms)})


def in_other_units(model: Model, length: float, mass: float, time: float = 1.0) -> Model:
    """The same model in units of ``length`` m, ``mass`` kg and ``time`` s (mm, t, s: 1e-3, 1e3, 1).

    Read as SI, the result is another model: with (1/s, 1/s³, 1/s) it is
    ``model`` scaled s times in size with the same materials, whose
    frequencies are those of ``model`` divided by s.
    """
    force = mass * length / time ** 2  # the new force unit in N
    pressure, density = force / length ** 2, mass / length ** 3

    def beam(b):
        return dataclasses.replace(b, E=b.E / pressure, G=b.G / pressure, rho=b.rho / density,
                                   A=b.A / length ** 2, Iy=b.Iy / length ** 4, Iz=b.Iz / length ** 4,
                                   J=b.J / length ** 4, Ip=b.Ip / length ** 4, length=b.length / length)

    def body(r):
        return dataclasses.replace(r, mass=r.mass / mass, com=r.com / length,
                                   inertia=r.inertia / (mass * length ** 2))

    def spring(s):
        scale = np.r_[np.full(3, force / length), np.full(3, force * length)]
        return dataclasses.replace(s, k=s.k / scale)

    return dataclasses.replace(model, points={p: x / length for p, x in model.points.items()},
                               beams=tuple(map(beam, model.beams)), rigids=tuple(map(body, model.rigids)),
                               springs=tuple(map(spring, model.springs)))


def free_chain(links: int = 4) -> Model:
    """Free-floating chain of bodies joined by springs: six rigid-body modes."""
    points, bodies, springs = {}, [], []
    for i in range(links):
        points[f"a{i}"], points[f"b{i}"] = np.array([i, 0.0, 0.0]), np.array([i + 0.5, 0.0, 0.0])
        bodies.append(make_rigid(f"m{i}", [f"a{i}", f"b{i}"], 2.0 + i, [i + 0.25, 0.1, 0.0], [0.3, 0.4, 0.5]))
        if i:
            points[f"s{i}"] = points[f"b{i - 1}"].copy()
            bodies[-1] = make_rigid(f"m{i}", [f"s{i}", f"b{i}"], 2.0 + i, [i + 0.25, 0.1, 0.0], [0.3, 0.4, 0.5])
            springs.append(make_spring(f"k{i}", f"b{i - 1}", f"s{i}", [1e4, 2e4, 3e4, 1e3, 2e3, 3e3]))
    used = {p for b in bodies for p in b.ports}
    return Model("free chain", {p: x for p, x in points.items() if p in used}, rigids=tuple(bodies),
                 springs=tuple(springs))


STARS = [(arms, length, width, height) for arms in (2, 3, 4, 5, 8, 12)
         for length, width, height in ((5.0, 0.125, 0.125), (2.0, 0.125, 0.125), (5.0, 0.2, 0.05))]


@pytest.mark.parametrize("arms, length, width, height", STARS)
def test_pinned_star_counts_what_the_fe_route_counts(arms, length, width, height):
    model = pinned_star(arms, length, width, height)
    expected = fe_frequencies(model, count=1, elements_per_beam=2).rigid_body_modes
    assert expected == (1 if arms == 2 else 0)  # only arms on one line turn about it
    assert rigid_body_mode_count(model) == expected
    assert natural_frequencies(model, count=1).rigid_body_modes == expected


@pytest.mark.parametrize("length, mass, time", [(1e-3, 1e3, 1.0), (1e3, 1e-3, 1.0), (1e-3, 1e-9, 1e-3),
                                                (1e3, 1e9, 1e3), (0.5, 0.125, 0.5)])
@pytest.mark.parametrize("model", [pinned_star(8), pinned_star(2, 2.0, 0.2, 0.05), free_chain()],
                         ids=["star8", "star2", "free chain"])
def test_counts_do_not_depend_on_units_or_size(model, length, mass, time):
    """Other units, and (where time scales with length) copies ×1e-3 … ×1e3 in size."""
    converted = in_other_units(model, length, mass, time)
    fe = fe_frequencies(converted, count=1, elements_per_beam=2)
    result, original = natural_frequencies(converted, count=3), natural_frequencies(model, count=3)
    assert result.rigid_body_modes == fe.rigid_body_modes == original.rigid_body_modes
    np.testing.assert_allclose(result.frequencies_hz / time, original.frequencies_hz, rtol=1e-9)


def test_free_chain_has_six_and_a_point_mass_three():
    assert rigid_body_mode_count(free_chain()) == 6
    lone = Model("point mass", {"p": np.zeros(3)}, rigids=(make_rigid("m", ["p"], 1.0, [0, 0, 0]),))
    assert rigid_body_mode_count(lone) == 3 == fe_frequencies(lone, count=1).rigid_body_modes


def test_star_modes_have_no_fake_zero_frequency_shapes():
    modes = mode_shapes(pinned_star(8), count=3)
    assert modes.rigid_body_modes == 0
    assert modes.stiffness_orthogonality_error < 1e-6


@pytest.mark.parametrize("seed", range(3))
def test_a_free_ring_has_six_zero_frequency_shapes_that_are_the_rigid_motions(seed):
    """A closed ring with no boundary end: its six shapes at ω = 0 (the null space of
    Ū_all there, balanced at the model's own scale since every ω² term vanishes at 0)
    are rigid motions of its points, u = a + θ × p, and span all six."""
    from random_models import random_model

    model = random_model("ring", seed)
    modes = mode_shapes(model, count=2, rigid_body=True)
    assert modes.rigid_body_modes == 6 == fe_frequencies(model, count=1).rigid_body_modes
    names = list(model.points)
    positions = np.array([model.points[p] for p in names])
    motions = np.concatenate([modes.point_displacements[p][:6] for p in names], axis=1).T   # (6 n_points, 6)
    arm = positions - positions.mean(axis=0)
    rigid = np.zeros((len(names), 6, 6))                  # each point's (u, θ) under the six unit motions
    rigid[:, :3, :3] = rigid[:, 3:, 3:] = np.eye(3)
    rigid[:, 0, 4], rigid[:, 0, 5] = arm[:, 2], -arm[:, 1]
    rigid[:, 1, 3], rigid[:, 1, 5] = -arm[:, 2], arm[:, 0]
    rigid[:, 2, 3], rigid[:, 2, 4] = arm[:, 1], -arm[:, 0]
    basis = rigid.reshape(-1, 6)
    coefficients = np.linalg.lstsq(basis, motions, rcond=None)[0]
    assert np.linalg.norm(basis @ coefficients - motions) <= 1e-8 * np.linalg.norm(motions)
    assert np.linalg.matrix_rank(coefficients, tol=1e-8 * np.abs(coefficients).max()) == 6


def test_a_model_held_still_has_no_rigid_body_mode():
    """rigid_motion.held_still reads a model with no joint and an end held in all six
    directions off its deduction, and the solve then skips the count: every model it says
    so of must have none by the full kinematic count, over random models of every kind
    (grounded and floating, with and without joints) and the bundled ones, and it must
    say so of the grounded ones without joints (both launchers among them)."""
    from builders import BUNDLED_MODELS
    from random_models import KINDS, random_model
    from test_joints import with_random_joints

    from linmstmm.deduction import Deduction
    from linmstmm.model import load_model
    from linmstmm.rigid_motion import held_still
    from linmstmm.topology import build_topology

    models = [random_model(kind, seed) for kind in KINDS for seed in range(20)]
    models += [with_random_joints(random_model(kind, seed), np.random.default_rng(3000 + seed))
               for kind in KINDS for seed in range(6)]
    models += [load_model(path) for path in BUNDLED_MODELS]
    still = []
    for model in models:
        if held_still(Deduction(build_topology(model))):
            assert rigid_body_mode_count(model) == 0, model.name
            still.append(model.name)
    assert {"MLRS-style launcher", "Light 4x4 rocket launcher"} <= set(still)
    assert 20 <= len(still) < len(models)
