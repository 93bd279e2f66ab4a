"""Connected parts and segments of a model's points (linmstmm.rigid_motion.connected_parts),
computed on arrays with scipy's connected components, against a plain flood fill.

Models: the bundled files, random models of every kind, and the same with
random directions of random springs released (joints split a model into
segments). The rigid-body counts of the jointed ones are checked against the
FE route's.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from builders import BUNDLED_MODELS
from random_models import KINDS, random_model

from linmstmm.fe import fe_frequencies
from linmstmm.model import Model, load_model
from linmstmm.rigid_motion import connected_parts, rigid_body_mode_count


def flood_filled(model: Model, through) -> list[list[str]]:
    """The point names of each group that the elements ``through`` accepts join,
    grown one point at a time from the first point not yet in a group; each group
    and the groups in order of first appearance in ``model.points``."""
    joins = [tuple(e.ports if e.kind == "rigid" else e.ends) for e in model.elements if through(e)]
    group_of: dict[str, int] = {}
    for start in model.points:
        if start in group_of:
            continue
        label, waiting = len(set(group_of.values())), [start]
        group_of[start] = label
        while waiting:
            point = waiting.pop()
            for ends in joins:
                if point in ends:
                    for other in ends:
                        if other not in group_of:
                            group_of[other] = label
                            waiting.append(other)
    return [[p for p in model.points if group_of[p] == label] for label in range(len(set(group_of.values())))]


def plain_parts(model: Model) -> tuple[list[list[str]], list[list[str]]]:
    return (flood_filled(model, lambda e: True),
            flood_filled(model, lambda e: not (e.kind == "spring" and e.released.size)))


def with_joints(model: Model, seed: int) -> Model:
    """``model`` with one to three random directions released on about half its springs."""
    rng = np.random.default_rng(seed)
    springs = []
    for spring in model.springs:
        if rng.random() < 0.5:
            release = np.zeros(6, dtype=bool)
            release[rng.choice(6, size=int(rng.integers(1, 4)), replace=False)] = True
            spring = dataclasses.replace(spring, k=np.where(release, 0.0, spring.k), release=release)
        springs.append(spring)
    return dataclasses.replace(model, name=f"{model.name} with joints", springs=tuple(springs))


MODELS = ([load_model(path) for path in BUNDLED_MODELS] + [random_model(kind, seed) for kind in KINDS
                                                           for seed in range(6)]
          + [with_joints(random_model(kind, seed), seed) for kind in KINDS for seed in range(6)])


@pytest.mark.parametrize("model", MODELS, ids=lambda model: model.name)
def test_parts_and_segments_are_those_of_a_flood_fill(model):
    assert connected_parts(model) == plain_parts(model)


@pytest.mark.parametrize("kind", ["tree", "floating_tree", "loops"])
def test_jointed_models_count_what_the_fe_route_counts(kind):
    for seed in range(3):
        model = with_joints(random_model(kind, seed), seed)
        assert rigid_body_mode_count(model) == fe_frequencies(model, count=1).rigid_body_modes


def reached_by_passes(joined) -> list:
    """The elements of ``joined`` not reached from the first one: passes over the
    elements, each adding those that share a point with the reached, until one
    adds none (what the model check did, quadratic in the elements)."""
    reached, points, grown = {0}, set(joined[0][1]), True
    while grown:
        grown = False
        for i, (_, ends) in enumerate(joined):
            if i not in reached and points.intersection(ends):
                reached.add(i)
                points.update(ends)
                grown = True
    return [entry for i, entry in enumerate(joined) if i not in reached]


@pytest.mark.parametrize("seed", range(40))
def test_the_model_checks_connection_as_passes_over_the_elements_do(seed):
    """linmstmm.connected.unreached (union–find over the points) against repeated passes,
    on random element lists: several parts, elements of one to four points, any order."""
    from linmstmm.connected import unreached

    rng = np.random.default_rng(seed)
    points = [f"p{i}" for i in range(int(rng.integers(2, 40)))]
    joined = [(f"e{i}", tuple(rng.choice(points, size=int(rng.integers(1, min(4, len(points)) + 1)), replace=False)))
              for i in range(int(rng.integers(1, 30)))]
    assert unreached(joined) == reached_by_passes(joined)


def test_a_long_chain_listed_backwards_is_connected():
    """Bodies first, then the springs between them (the builders' order), so that each
    pass of the old check reached one more body: 2,000 of them, found connected."""
    from linmstmm.connected import unreached

    bodies = [(f"b{i}", (f"p{i}", f"q{i}")) for i in range(2000)]
    springs = [(f"s{i}", (f"q{i}", f"p{i + 1}")) for i in range(1999)]
    assert unreached(bodies + springs) == []
    assert unreached(bodies + springs[:999] + springs[1000:]) == bodies[1000:] + springs[1000:]
