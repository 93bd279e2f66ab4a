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
