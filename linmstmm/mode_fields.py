"""The states and fields of a set of modes, and their inner products.

From the boundary unknowns z̄ the element transfer equations give the state
at every port and the beam transfer matrix the field inside each beam (at
stations and at Gauss–Legendre points); the mass and stiffness Gram matrices
of the augmented eigenvectors are integrated from them (:class:`_Fields`).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from linmstmm.deduction import Deduction
from linmstmm.elements.beam import beam_states
from linmstmm.geometry import cross_rows
from linmstmm.model import Model

#: Gauss–Legendre points along a beam beyond its largest wavenumber × length.
EXTRA_QUADRATURE_POINTS = 20


@dataclass(frozen=True)
class _Bodies:
    """The rigid bodies of a topology as arrays, in element order (R of them).

    names : (R,). elements : (R,) their transfer element indices. mass : (R,) kg.
    inertia : (R, 3, 3) kg m² about the mass centre, inertial axes. arms : (R, 3) m,
    mass centre less the first port's position.
    """

    names: tuple
    elements: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    arms: np.ndarray


@dataclass(frozen=True)
class _Springs:
    """The springs of a topology as arrays, in element order (S of them).

    elements : (S,) transfer element indices. ends : (S, 2) the port of ends[0] and
    of ends[1]. axes : (S, 3, 3) rows the spring's local axes. k : (S, 6) N/m and
    N m/rad, 0 where infinite (a rigid direction stores no strain energy).
    """

    elements: np.ndarray
    ends: np.ndarray
    axes: np.ndarray
    k: np.ndarray


@dataclass(frozen=True, eq=False)
class _Fields:
    """Everything linear in z̄ for a set of modes; ``apply`` recombines modes.

    element_states : per transfer element (n, ports, 12), topology convention.
    station_states, quadrature_states : beam -> (n, s, 12), traversal convention.
    """

    names: tuple
    points: tuple
    element_states: list
    station_states: dict
    quadrature_states: dict
    zbar: np.ndarray
    topology: object
    stations: dict
    quadrature: dict

    @classmethod
    def of(cls, model, deduction, omega, zbar, n_stations):
        topology = deduction.topology
        states = _element_states(deduction, omega, zbar)
        index = {el.name: e for e, el in enumerate(topology.elements)}
        stations, rules, at_stations, at_nodes = {}, {}, {}, {}
        for beam in model.beams:
            e = index[beam.name]
            stations[beam.name] = np.linspace(0.0, beam.length, n_stations)
            rules[beam.name] = quadrature(beam, omega.max(initial=0.0))
            both = _beam_states(beam, topology.elements[e], omega, states[e],
                                np.concatenate([stations[beam.name], rules[beam.name][0]]))
            at_stations[beam.name], at_nodes[beam.name] = both[:, :n_stations], both[:, n_stations:]
        return cls(tuple(index), tuple(model.points), states, at_stations, at_nodes, zbar, topology, stations, rules)

    def apply(self, transform: np.ndarray) -> _Fields:
        """The fields of the modes ``transform.T @ raw modes`` (transform (n_raw, n))."""
        def combine(array):
            return np.einsum("rk,r...->k...", transform, array)
        return _Fields(self.names, self.points, [combine(s) for s in self.element_states],
                       {b: combine(s) for b, s in self.station_states.items()},
                       {b: combine(s) for b, s in self.quadrature_states.items()},
                       combine(self.zbar), self.topology, self.stations, self.quadrature)

    # -- by point and by body -------------------------------------------------
    @property
    def port_states(self) -> dict[str, np.ndarray]:
        return {f"{element.name}@{port.point}": self.element_states[e][:, p]
                for e, element in enumerate(self.topology.elements)
                for p, port in enumerate(element.ports)}

    @property
    def point_displacements(self) -> dict[str, np.ndarray]:
        """model point -> (n, 6), from the first port found at the point, in model order."""
        found = {}
        for e, element in enumerate(self.topology.elements):
            for p, port in enumerate(element.ports):
                found.setdefault(port.point, self.element_states[e][:, p, :6])
        return {point: found[point] for point in self.points}

    @property
    def com_displacements(self) -> dict[str, np.ndarray]:
        """rigid body -> (n, 6) translation and rotation of its mass centre."""
        return dict(zip(self._bodies.names, self._coms()))

    def displacement_samples(self) -> np.ndarray:
        """(n, s, 6) displacements at every point and beam quadrature node."""
        at_points = np.stack(list(self.point_displacements.values()), axis=1)
        at_nodes = [s[..., :6] for s in self.quadrature_states.values()]
        return np.concatenate([at_points, *at_nodes], axis=1)

    # -- the body operators ---------------------------------------------------
    def mass_gram(self, axis_weights=np.ones(3)) -> np.ndarray:
        """(n, n) ⟨M V^k, V^p⟩; ``axis_weights`` (3,) scale the translational mass along x, y, z."""
        axis_weights = np.asarray(axis_weights, float)
        bodies, coms = self._bodies, self._coms()  # every rigid body at once: (R, n, 6)
        translation, rotation = coms[..., :3], coms[..., 3:]
        gram = (np.einsum("rka,rpa,ra->kp", translation, translation, np.outer(bodies.mass, axis_weights))
                + np.einsum("rka,rab,rpb->kp", rotation, bodies.inertia, rotation))
        return gram + _gram(self._beam_mass_measures(axis_weights), self.zbar.shape[0])

    def stiffness_gram(self) -> np.ndarray:
        """(n, n) ⟨K V^k, V^p⟩ from the strain energy of springs and beams."""
        stretch = self._spring_motions()  # every spring at once: (S, n, 6)
        gram = np.einsum("rka,rpa,ra->kp", stretch, stretch, self._springs.k)
        return gram + _gram(self._beam_strain_measures(), self.zbar.shape[0])

    def _beam_mass_measures(self, axis_weights):
        for beam, (nodes, weights) in self._beams():
            states = self.quadrature_states[beam.name]
            yield (states[..., :3].reshape(len(states), -1),
                   np.outer(beam.rho * beam.A * weights, axis_weights).ravel())
            torsion = states[..., 3:6] @ np.asarray(beam.axes, float)[0]
            yield torsion, beam.rho * beam.Ip * weights

    def _beam_strain_measures(self):
        for beam, (nodes, weights) in self._beams():
            states = self.quadrature_states[beam.name]
            axes = np.asarray(beam.axes, float)
            moment = states[..., 6:9] @ axes.T  # local mx, my, mz
            force = states[..., 9:12] @ axes.T
            terms = [(moment[..., 1], beam.E * beam.Iy), (moment[..., 2], beam.E * beam.Iz)]
            if beam.axial:
                terms.append((force[..., 0], beam.E * beam.A))
            if beam.torsion:
                terms.append((moment[..., 0], beam.G * beam.J))
            for values, rigidity in terms:
                yield values, weights / rigidity

    def _coms(self) -> np.ndarray:
        """(R, n, 6) mass-centre displacement u_c = u_p + θ × (c − p) of each rigid body, from
        its first port."""
        bodies = self._bodies
        ports = self._gathered(bodies.elements, np.zeros(bodies.elements.size, int))
        theta = ports[..., 3:6]
        return np.concatenate([ports[..., :3] + cross_rows(theta, bodies.arms[:, None, :]), theta], axis=2)

    def _spring_motions(self) -> np.ndarray:
        """(S, n, 6) each spring's relative motion, its ends[1] less its ends[0], in its own axes."""
        springs = self._springs
        first, second = (self._gathered(springs.elements, springs.ends[:, end]) for end in (0, 1))
        delta = second - first
        return np.concatenate([np.einsum("rab,rkb->rka", springs.axes, delta[..., :3]),
                               np.einsum("rab,rkb->rka", springs.axes, delta[..., 3:])], axis=2)

    def _gathered(self, elements: np.ndarray, ports: np.ndarray) -> np.ndarray:
        """(m, n, 6) displacement and rotation at port ``ports[i]`` of element ``elements[i]``."""
        if not elements.size:
            return np.zeros((0, self.zbar.shape[0], 6))
        return np.stack([self.element_states[e][:, p, :6] for e, p in zip(elements.tolist(), ports.tolist())])

    @functools.cached_property
    def _bodies(self) -> _Bodies:
        """The rigid bodies' arrays (:class:`_Bodies`), made once."""
        found = [(e, element) for e, element in enumerate(self.topology.elements) if element.kind == "rigid"]
        return _Bodies(tuple(element.name for _, element in found), np.array([e for e, _ in found], int),
                       np.array([element.record.mass for _, element in found], float).reshape(-1),
                       np.array([element.record.inertia for _, element in found], float).reshape(-1, 3, 3),
                       np.array([np.asarray(element.record.com, float) - element.ports[0].position
                                 for _, element in found], float).reshape(-1, 3))

    @functools.cached_property
    def _springs(self) -> _Springs:
        """The springs' arrays (:class:`_Springs`), made once."""
        found = [(e, element) for e, element in enumerate(self.topology.elements) if element.kind == "spring"]
        ends = [[next(p for p, port in enumerate(element.ports) if port.point == end) for end in element.record.ends]
                for _, element in found]
        stiffness = np.array([element.record.k for _, element in found], float).reshape(-1, 6)
        return _Springs(np.array([e for e, _ in found], int), np.array(ends, int).reshape(-1, 2),
                        np.array([element.record.axes for _, element in found], float).reshape(-1, 3, 3),
                        np.where(np.isfinite(stiffness), stiffness, 0.0))  # a rigid direction stores no energy

    def _beams(self):
        for element in self.topology.elements:
            if element.kind == "beam":
                yield element.record, self.quadrature[element.name]


def _gram(measures, n: int) -> np.ndarray:
    """(n, n) Σ X diag(w) Xᵀ over the (X (n, d), w (d,)) measures; zeros if there are none
    (no spring or beam strains under a lone rigid body)."""
    return sum((np.einsum("kd,pd,d->kp", X, X, w) for X, w in measures), np.zeros((n, n)))


def _element_states(deduction: Deduction, omega: np.ndarray, zbar: np.ndarray) -> list:
    """Per transfer element, (n, ports, 12): the state at each of its ports.

    Output ports come from ``Deduction.port_states``; an input port is linked
    to the output of its upstream element or to a tip (boundary or cut side).
    The root's port is the root's own state (:meth:`Deduction.root_given`): its
    fixed components zero and the others z̄'s, which the main transfer equation
    makes the carried state equal to. The carried state itself differs from it by
    the equation's residual, which is the null vector's rounding blown up by
    the carry (on a random tree's twelfth mode a clamped root "moved" by 2.4 % of
    the mode's largest point displacement with the compiled engine's roots, 0.4 %
    with the numpy engine's).
    """
    outputs, _ = deduction.port_states(omega)
    n = omega.size
    outputs[deduction.topology.order[-1]] = deduction.root_given(n)

    def evaluate(state):
        return np.einsum("nik,nk->ni", state.matrix, zbar[:, state.columns])

    states = []
    for e, element in enumerate(deduction.topology.elements):
        ports = []
        for p, port in enumerate(element.ports):
            if p == element.output:
                ports.append(evaluate(outputs[e]))
            elif port.link[0] == "element":
                ports.append(evaluate(outputs[port.link[1]]))
            else:
                ports.append(evaluate(deduction.tip_state(port.link, n)))
        states.append(np.stack(ports, axis=1))
    return states


def _beam_states(beam, element, omega, port_states, stations) -> np.ndarray:
    """(n, s, 12) states at ``stations`` (m from ends[0]) by transfer from the input end.

    States are in the traversal convention of the topology (forces: what the
    part nearer the input exerts on the part beyond).
    """
    reverse = element.inputs[0] == 1
    distances = beam.length - stations if reverse else stations
    return beam_states(beam, omega, port_states[:, element.inputs[0]], distances, reverse)


def quadrature(beam, omega_max: float) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre (nodes (q,) m, weights (q,) m) on [0, L], enough for the highest mode.

    q = (largest wavenumber at omega_max) × L + EXTRA_QUADRATURE_POINTS, where
    the wavenumbers are bending (ρAω²/EI)^¼, axial ω√(ρ/E), torsion ω√(ρIp/GJ).
    """
    count = int(np.ceil(max(beam.wavenumbers(omega_max).values()) * beam.length)) + EXTRA_QUADRATURE_POINTS
    nodes, weights = _gauss_legendre(count)
    half = beam.length / 2
    return half * (nodes + 1), half * weights


@functools.lru_cache(maxsize=64)
def _gauss_legendre(count: int) -> tuple[np.ndarray, np.ndarray]:
    """numpy's ``leggauss(count)`` on [−1, 1], made once per count (0.5 ms each), read-only."""
    nodes, weights = np.polynomial.legendre.leggauss(count)
    nodes.flags.writeable = weights.flags.writeable = False
    return nodes, weights


def _station_positions(model: Model, beam, fields: _Fields) -> np.ndarray:
    """(s, 3) positions of a beam's stations, m."""
    start = np.asarray(model.points[beam.ends[0]], float)
    return start + fields.stations[beam.name][:, None] * np.asarray(beam.axes, float)[0]
