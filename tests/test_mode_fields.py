"""The Gram matrices of a set of modes, all rigid bodies and springs at once, against the
element-by-element sums they replace (the formulas of docs/method.md, written out here).

The Gram matrices are bilinear in the port states, so any states serve: random ones on the
topologies of random models (bodies with offset mass centres and full inertia tensors,
springs with oblique axes and rigid directions, beams), which no mode would single out.
"""
from __future__ import annotations

import numpy as np
import pytest
from random_models import random_model

from linmstmm.mode_fields import _Fields, quadrature
from linmstmm.topology import build_topology


def _random_fields(model, modes: int, rng) -> _Fields:
    """A :class:`_Fields` of ``model`` with random states at every port and beam node."""
    topology = build_topology(model)
    states = [rng.standard_normal((modes, len(element.ports), 12)) for element in topology.elements]
    rules = {beam.name: quadrature(beam, 50.0) for beam in model.beams}
    nodes = {name: rng.standard_normal((modes, nodes.size, 12)) for name, (nodes, _) in rules.items()}
    return _Fields(tuple(element.name for element in topology.elements), tuple(model.points), states, {}, nodes,
                   rng.standard_normal((modes, 4)), topology, {}, rules)


def _reference_grams(fields: _Fields, axis_weights: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
    """(mass Gram, stiffness Gram, mass-centre motions) summed element by element: a body's
    ½ m u·u and ½ θ·Iθ at its mass centre (its inertia by its principal axes), a spring's
    ½ k Δ² in its axes (none in a rigid direction), a beam's ρA u·u, ρIp θx² and M²/EI, N²/EA,
    Mx²/GJ over its Gauss–Legendre nodes."""
    n = fields.zbar.shape[0]
    mass, stiffness, coms = np.zeros((n, n)), np.zeros((n, n)), {}

    def add(gram, values, weights):
        gram += values @ np.diag(weights) @ values.T

    for e, element in enumerate(fields.topology.elements):
        record = element.record
        if element.kind == "rigid":
            port = fields.element_states[e][:, 0]
            arm = np.asarray(record.com, float) - np.asarray(element.ports[0].position, float)
            com = np.concatenate([port[:, :3] + np.cross(port[:, 3:6], arm), port[:, 3:6]], axis=1)
            coms[element.name] = com
            principal, axes = np.linalg.eigh(np.asarray(record.inertia, float))
            add(mass, com[:, :3], record.mass * axis_weights)
            add(mass, com[:, 3:] @ axes, principal)
        elif element.kind == "spring":
            ports = [next(p for p, port in enumerate(element.ports) if port.point == end) for end in record.ends]
            delta = fields.element_states[e][:, ports[1], :6] - fields.element_states[e][:, ports[0], :6]
            axes = np.asarray(record.axes, float)
            local = np.concatenate([delta[:, :3] @ axes.T, delta[:, 3:] @ axes.T], axis=1)
            finite = np.isfinite(record.k)
            add(stiffness, local[:, finite], np.asarray(record.k, float)[finite])
        elif element.kind == "beam":
            states, (_, weights) = fields.quadrature_states[element.name], fields.quadrature[element.name]
            axes = np.asarray(record.axes, float)
            for a in range(3):
                add(mass, states[..., a], record.rho * record.A * weights * axis_weights[a])
            add(mass, states[..., 3:6] @ axes[0], record.rho * record.Ip * weights)
            moment, force = states[..., 6:9] @ axes.T, states[..., 9:12] @ axes.T
            add(stiffness, moment[..., 1], weights / (record.E * record.Iy))
            add(stiffness, moment[..., 2], weights / (record.E * record.Iz))
            if record.axial:
                add(stiffness, force[..., 0], weights / (record.E * record.A))
            if record.torsion:
                add(stiffness, moment[..., 0], weights / (record.G * record.J))
    return mass, stiffness, coms


@pytest.mark.parametrize("kind, seed", [("tree", 3), ("loops", 5), ("floating_loops", 2), ("ring", 4)])
def test_mass_and_stiffness_grams_equal_their_element_sums(kind, seed):
    model = random_model(kind, seed)
    fields = _random_fields(model, 5, np.random.default_rng(seed))
    weights = np.array([1.0, 2.0, 3.0])
    mass, stiffness, coms = _reference_grams(fields, weights)
    assert model.rigids
    np.testing.assert_allclose(fields.mass_gram(weights), mass, rtol=0, atol=1e-13 * np.abs(mass).max())
    np.testing.assert_allclose(fields.stiffness_gram(), stiffness, rtol=0, atol=1e-13 * np.abs(stiffness).max())
    assert list(fields.com_displacements) == list(coms)
    for name, motion in fields.com_displacements.items():
        np.testing.assert_allclose(motion, coms[name], rtol=0, atol=1e-14 * np.abs(coms[name]).max())


def test_rigid_directions_and_beams_are_in_the_models_drawn():
    """The models above hold what the sums must get right: a spring with a rigid
    direction, a beam, a body whose mass centre is off its first port."""
    models = [random_model(kind, seed) for kind, seed in [("tree", 3), ("loops", 5), ("floating_loops", 2),
                                                          ("ring", 4)]]
    assert any(np.isinf(spring.k).any() for model in models for spring in model.springs)
    assert any(model.beams for model in models)
