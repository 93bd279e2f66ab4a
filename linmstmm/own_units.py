"""The model's own units: how large a displacement, rotation, moment and force are.

Ū_all mixes metres, radians, newton-metres and newtons; how its rows and columns
compare depends on the units the model is written in (in µm, pg and µs a force
is 1e9 times its size in newtons, a length 1e6 times). Scaled by the sizes
here, Ū_all is the same matrix whatever those units, so that a decision on its
singular values (:mod:`linmstmm.nullspace`) is too.
"""
from __future__ import annotations

import math

import numpy as np


def extent(topology) -> float:
    """The largest distance between two ports of the model's elements.

    Parameters
    ----------
    topology : linmstmm.topology.Topology
        The model's deduced structure.

    Returns
    -------
    float
        Model length unit; 0 for a model whose ports all coincide.
    """
    # each point once (a port stands at its point): half the ports of the launcher to stack
    at = {port.point: port.position for element in topology.elements for port in element.ports}
    if not at:
        return 0.0
    positions = np.array(list(at.values()), float)
    span = positions.max(axis=0) - positions.min(axis=0)
    return math.sqrt(span.dot(span))  # numpy.linalg.norm's sum and root, without its checks


def unit_sizes(topology, frequency: float) -> np.ndarray:
    """The sizes of a displacement, a rotation, a moment and a force in the model's own units.

    A length L: the model's :func:`extent`, or where every port coincides the
    radius of gyration of its rigid bodies (1 where neither exists); a force
    F = m L ω² for the model's whole mass m (rigid bodies and beams) moved by L
    at ω (1 where that vanishes). Each moves with the units the model is
    written in: L with the length unit, F with mass × length / time².

    Parameters
    ----------
    topology : linmstmm.topology.Topology
        The model's deduced structure.
    frequency : float
        ω, rad/s: the model's own frequency scale
        (:func:`linmstmm.nullspace.characteristic_frequencies`).

    Returns
    -------
    numpy.ndarray, shape (4,)
        [L, 1, F L, F]: m, rad, N m and N in the model's units.
    """
    records = [element.record for element in topology.elements if element.record is not None]
    mass = sum(record.mass for record in records if record.kind in ("rigid", "beam"))
    length = extent(topology) or _gyration_radius(records)
    force = mass * length * frequency ** 2
    force = force if np.isfinite(force) and force > 0 else 1.0
    return np.array([length, 1.0, force * length, force])


def _gyration_radius(records) -> float:
    """√(tr I / 2m) over the rigid bodies (I about their mass centres), 1 without them."""
    rigids = [record for record in records if record.kind == "rigid" and record.mass > 0]
    mass = sum(record.mass for record in rigids)
    trace = sum(np.trace(record.inertia) for record in rigids)
    return float(np.sqrt(trace / (2 * mass))) if mass > 0 and trace > 0 else 1.0
