"""Seeded random models for cross-checking the transfer matrix method against FE.

``random_model(kind, seed)`` draws a small model (at most ~15 elements) from a
numpy Generator: rigid bodies with random inertia tensors (a random rotation
of the principal moments of a random box) and mass centres off their ports,
springs with random stiffnesses and orthonormal axes (sometimes one ``inf``
direction), steel beams 0.5–2 m long with random sections and orientations,
ground springs, junctions (three or more ends at one point) and tip bodies
(one-port rigid bodies). Magnitudes put the first frequencies at roughly
1–1000 Hz.

Kinds: ``tree`` (grounded), ``floating_tree`` (no boundary conditions: six
rigid-body modes), ``loops`` (grounded, one or two closed loops),
``floating_loops`` and ``ring`` (a closed ring with no boundary end at all).

Also here: graph facts the tests check against (loop count, cuttable points,
boundary ends) and :func:`mstmm_frequencies`, the solve pipeline with a
forced root and loop cuts.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from builders import make_beam, make_rigid, make_spring
from linmstmm.model import Model
from linmstmm.solve import frequency_finder

KINDS = ("tree", "floating_tree", "loops", "floating_loops", "ring")
_COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """(3, 3) uniformly random proper rotation (rows orthonormal, det +1)."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def random_direction(rng: np.random.Generator) -> np.ndarray:
    v = rng.standard_normal(3)
    return v / np.linalg.norm(v)


@dataclass
class _Body:
    """A rigid body under construction (ports are added as things attach)."""

    name: str
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    ports: list = field(default_factory=list)


class Sketch:
    """Mutable model under construction; ``model()`` freezes it into records."""

    def __init__(self, rng: np.random.Generator, name: str):
        self.rng = rng
        self.name = name
        self.points: dict[str, np.ndarray] = {}
        self.ends: dict[str, int] = {}
        self.bodies: list[_Body] = []
        self.beams: list = []
        self.springs: list = []
        self.boundary: dict[str, np.ndarray] = {}

    # -- points ---------------------------------------------------------------
    def point(self, position) -> str:
        name = f"p{len(self.points)}"
        self.points[name] = np.asarray(position, float)
        self.ends[name] = 0
        return name

    def fix(self, point: str, components=_COMPONENTS) -> None:
        self.boundary[point] = np.isin(_COMPONENTS, components)

    def leaves(self) -> list[str]:
        """Points with one element end and no boundary condition."""
        return [p for p, n in self.ends.items() if n == 1 and p not in self.boundary]

    def site(self, junction_chance: float = 0.15) -> str:
        """A point to attach the next element to: a leaf, a new body port, or
        (sometimes) a connection point, which makes a junction."""
        rng = self.rng
        connections = [p for p, n in self.ends.items() if n == 2 and p not in self.boundary]
        if connections and rng.random() < junction_chance:
            return str(rng.choice(connections))
        leaves = self.leaves()
        if self.bodies and (not leaves or rng.random() < 0.35):
            return self.port(self.bodies[rng.integers(len(self.bodies))])
        return str(rng.choice(leaves)) if leaves else str(rng.choice(list(self.points)))

    # -- elements ---------------------------------------------------------------
    def body(self, at: str | None = None, com=None) -> _Body:
        """A rigid body with its first port at ``at`` (if given), mass centre at
        ``com`` or 0.05–0.3 m from ``at``."""
        rng = self.rng
        mass = rng.uniform(1.0, 20.0)
        a, b, c = rng.uniform(0.1, 0.5, 3)
        principal = mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
        rotation = random_rotation(rng)
        inertia = rotation.T @ np.diag(principal) @ rotation
        if com is None:
            com = self.points[at] + rng.uniform(0.05, 0.3) * random_direction(rng)
        body = _Body(f"body{len(self.bodies)}", mass, np.asarray(com, float), (inertia + inertia.T) / 2)
        self.bodies.append(body)
        if at is not None:
            self._use(at)
            body.ports.append(at)
        return body

    def port(self, body: _Body, position=None) -> str:
        """A new port on ``body`` (default: 0.05–0.3 m from its mass centre)."""
        if position is None:
            position = body.com + self.rng.uniform(0.05, 0.3) * random_direction(self.rng)
        p = self.point(position)
        self._use(p)
        body.ports.append(p)
        return p

    def beam(self, a: str, b: str | None = None) -> str:
        """A steel beam from ``a`` (to ``b``, or to a new point 0.5–2 m away); returns its far end."""
        rng = self.rng
        if b is None:
            b = self.point(self.points[a] + rng.uniform(0.5, 2.0) * random_direction(rng))
        width, height = rng.uniform(0.01, 0.05, 2)
        Iz, Iy = width * height ** 3 / 12, height * width ** 3 / 12
        J = rng.uniform(0.3, 1.0) * min(Iy, Iz) * 2
        self.beams.append(make_beam(f"beam{len(self.beams)}", a, b, self.points, A=width * height,
                                    Iy=Iy, Iz=Iz, J=J, y_hint=random_direction(rng)))
        self._use(a)
        self._use(b)
        return b

    def spring(self, a: str, b: str | None = None, inf_chance: float = 0.25) -> str:
        """A spring from ``a`` (to ``b``, or to a new coinciding point); returns its far end."""
        rng = self.rng
        if b is None:
            b = self.point(self.points[a])
        k = np.r_[10 ** rng.uniform(4, 6, 3), 10 ** rng.uniform(2, 4, 3)]
        if rng.random() < inf_chance:
            k[rng.integers(6)] = np.inf
        axes = random_rotation(rng) if rng.random() < 0.8 else None
        self.springs.append(make_spring(f"spring{len(self.springs)}", a, b, k, axes))
        self._use(a)
        self._use(b)
        return b

    def ground_spring(self, at: str) -> None:
        self.fix(self.spring(at))

    def tip_body(self, at: str) -> None:
        """A one-port rigid body at ``at``."""
        self.body(at)

    def _use(self, point: str) -> None:
        self.ends[point] += 1

    # -- result ----------------------------------------------------------------
    def model(self) -> Model:
        rigids = tuple(make_rigid(b.name, b.ports, b.mass, b.com, b.inertia) for b in self.bodies)
        return Model(self.name, dict(self.points), rigids=rigids, beams=tuple(self.beams),
                     springs=tuple(self.springs), boundary=dict(self.boundary))


# --------------------------------------------------------------------------
# Growing trees and closing loops

def _grow(sketch: Sketch, start: str, n_elements: int) -> None:
    """Attach ``n_elements`` random elements, the first at ``start``."""
    rng = sketch.rng
    at = start
    for _ in range(n_elements):
        kind = rng.choice(("rigid", "beam", "spring"), p=(0.35, 0.4, 0.25))
        if kind == "rigid":
            sketch.body(at)
        elif kind == "beam":
            sketch.beam(at)
        else:
            sketch.spring(at)
        at = sketch.site()


def _finish(sketch: Sketch, grounded: bool) -> None:
    """Give every dangling spring end a tip body (or, grounded, sometimes the ground),
    put a tip body on some free beam ends, and some ground springs."""
    rng = sketch.rng
    spring_ends = {p for s in sketch.springs for p in s.ends}
    for leaf in sketch.leaves():
        if leaf in spring_ends:
            if grounded and rng.random() < 0.4:
                sketch.fix(leaf)
            else:
                sketch.tip_body(leaf)
        elif rng.random() < 0.3:
            sketch.tip_body(leaf)
    if grounded:
        for _ in range(rng.integers(0, 3)):
            sketch.ground_spring(sketch.site(junction_chance=0.0))


def _root_point(sketch: Sketch, grounded: bool) -> str:
    """The first point; grounded: fixed (sometimes pinned or a few components)."""
    start = sketch.point(sketch.rng.uniform(-1.0, 1.0, 3))
    if grounded:
        r = sketch.rng.random()
        components = _COMPONENTS if r < 0.7 else ("x", "y", "z") if r < 0.85 else tuple(
            sketch.rng.choice(_COMPONENTS, size=4, replace=False))
        sketch.fix(start, components)
    return start


def _close_loop(sketch: Sketch) -> None:
    """Add a beam or a spring between two parts of the structure."""
    rng = sketch.rng
    if sketch.bodies and rng.random() < 0.5:  # spring from any point to a new port of another body
        a = sketch.site(junction_chance=0.3)
        owners = [b for b in sketch.bodies if a not in b.ports]
        if owners:
            body = owners[rng.integers(len(owners))]
            sketch.spring(a, sketch.port(body, sketch.points[a]))
            return
    candidates = [p for p in sketch.points if p not in sketch.boundary]
    a = str(rng.choice(candidates))
    far = [p for p in candidates
           if 0.4 <= np.linalg.norm(sketch.points[p] - sketch.points[a]) <= 2.5]
    if far:
        sketch.beam(a, str(rng.choice(far)))
    else:
        sketch.beam(a, sketch.port(sketch.bodies[0]) if sketch.bodies else None)


def _tree(sketch: Sketch, grounded: bool) -> None:
    start = _root_point(sketch, grounded)
    _grow(sketch, start, int(sketch.rng.integers(4, 9)))


def _ring(sketch: Sketch) -> None:
    """3–5 bodies round a circle, neighbours joined by a spring or a beam; no boundary."""
    rng = sketch.rng
    n = int(rng.integers(3, 6))
    rotation = random_rotation(rng)
    angles = 2 * np.pi * (np.arange(n) + rng.uniform(-0.15, 0.15, n)) / n
    centres = 1.2 * np.c_[np.cos(angles), np.sin(angles), np.zeros(n)] @ rotation
    bodies = [sketch.body(com=centre + 0.1 * random_direction(rng)) for centre in centres]
    for i, body in enumerate(bodies):
        nxt = bodies[(i + 1) % n]
        middle = (centres[i] + centres[(i + 1) % n]) / 2
        if rng.random() < 0.5:
            sketch.spring(sketch.port(body, middle), sketch.port(nxt, middle))
        else:
            chord = centres[(i + 1) % n] - centres[i]
            sketch.beam(sketch.port(body, middle - 0.3 * chord), sketch.port(nxt, middle + 0.3 * chord))


def random_model(kind: str, seed: int) -> Model:
    """A random model of ``kind`` (see KINDS), reproducible from ``seed``."""
    rng = np.random.default_rng([KINDS.index(kind), seed])
    sketch = Sketch(rng, f"{kind} {seed}")
    grounded = kind in ("tree", "loops")
    if kind == "ring":
        _ring(sketch)
        return sketch.model()
    _tree(sketch, grounded)
    if kind in ("loops", "floating_loops"):
        for _ in range(int(rng.integers(1, 3))):
            _close_loop(sketch)
    _finish(sketch, grounded)
    return sketch.model()


# --------------------------------------------------------------------------
# Graph facts, computed from the records (independent of linmstmm.topology)

def element_ends(model: Model) -> dict[str, list[str]]:
    """point -> names of the elements with an end there (once per end)."""
    ends = {p: [] for p in model.points}
    for rigid in model.rigids:
        for p in rigid.ports:
            ends[p].append(rigid.name)
    for element in model.beams + model.springs:
        for p in element.ends:
            ends[p].append(element.name)
    return ends


def _components(model: Model, skip: str | None = None) -> dict[str, str]:
    """element name -> representative of its connected part, ignoring point ``skip``."""
    parent = {e.name: e.name for e in model.elements}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for point, names in element_ends(model).items():
        if point != skip:
            for name in names[1:]:
                parent[find(name)] = find(names[0])
    return {name: find(name) for name in parent}


def loop_count(model: Model) -> int:
    """Independent closed loops: edges − vertices + parts of the element graph
    (a point with k ≥ 3 ends, or 2 ends and a boundary, is a junction vertex)."""
    edges = vertices = 0
    for point, names in element_ends(model).items():
        junction = len(names) >= 3 or (len(names) == 2 and model.fixed_mask(point).any())
        if junction:
            vertices += 1
            edges += len(names)
        elif len(names) == 2:
            edges += 1
    vertices += len(model.elements)
    parts = len(set(_components(model).values()))
    return edges - vertices + parts


def loop_connections(model: Model) -> list[str]:
    """Connection points (two ends, no boundary) that lie on a closed loop."""
    found = []
    for point, names in element_ends(model).items():
        if len(names) != 2 or model.fixed_mask(point).any():
            continue
        parts = _components(model, skip=point)
        if parts[names[0]] == parts[names[1]]:
            found.append(point)
    return found


def junctions(model: Model) -> list[str]:
    """Points with three or more element ends."""
    return [p for p, names in element_ends(model).items() if len(names) >= 3]


def tip_bodies(model: Model) -> list[str]:
    return [r.name for r in model.rigids if len(r.ports) == 1]


def boundary_labels(model: Model) -> list[str]:
    """Labels of the boundary ends (usable as ``root``): points with one end or a
    boundary condition, and the free side of each tip body."""
    labels = [p for p, names in element_ends(model).items()
              if len(names) == 1 or model.fixed_mask(p).any()]
    return labels + [f"{name} free end" for name in tip_bodies(model)]


# --------------------------------------------------------------------------
# Comparing solves: other roots, cuts and record orders

def relative(a, b) -> float:
    """max |a/b − 1| over equal-length arrays (inf if the lengths differ)."""
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a / b - 1.0), initial=0.0)) if a.shape == b.shape else np.inf


def reordered(m, shift: int):
    """The same model with each kind of element record rotated by ``shift``."""
    def roll(records):
        k = shift % len(records) if records else 0
        return records[k:] + records[:k]
    return dataclasses.replace(m, rigids=roll(m.rigids), beams=roll(m.beams), springs=roll(m.springs))


def mstmm_frequencies(model: Model, count: int = 10, root: str | None = None,
                      cut_at=()) -> np.ndarray:
    """Elastic frequencies (Hz) as ``natural_frequencies`` finds them, but with
    ``root`` and the loop cuts ``cut_at`` chosen (no mpmath escalation)."""
    _, finder, _ = frequency_finder(model, root=root, cut_at=cut_at)
    return finder.find(count, None).roots / (2 * np.pi)


# --------------------------------------------------------------------------
# Writing a model file (to validate with load_model and to reproduce a seed)

def _toml_value(value) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    array = np.asarray(value)
    if array.ndim == 0:
        number = float(array)
        return "inf" if np.isposinf(number) else repr(number)
    return "[" + ", ".join(_toml_value(v) for v in (value if isinstance(value, (list, tuple)) else array)) + "]"


def to_toml(model: Model) -> str:
    """The model as a model file (docs/model-format.md)."""
    lines = [f"name = {_toml_value(model.name)}", "", "[points]"]
    lines += [f"{p} = {_toml_value(x)}" for p, x in model.points.items()]
    for r in model.rigids:
        lines += ["", "[[rigid]]", f"name = {_toml_value(r.name)}", f"ports = {_toml_value(list(r.ports))}",
                  f"mass = {_toml_value(r.mass)}", f"com = {_toml_value(r.com)}",
                  f"inertia = {_toml_value(r.inertia)}"]
    for b in model.beams:
        lines += ["", "[[beam]]", f"name = {_toml_value(b.name)}", f"ends = {_toml_value(list(b.ends))}"]
        lines += [f"{key} = {_toml_value(getattr(b, key))}" for key in ("E", "G", "rho", "A", "Iy", "Iz", "J", "Ip")]
        lines += [f"y_axis = {_toml_value(b.axes[1])}"]
    for s in model.springs:
        lines += ["", "[[spring]]", f"name = {_toml_value(s.name)}", f"ends = {_toml_value(list(s.ends))}",
                  f"k = {_toml_value(s.k)}", f"axes = {_toml_value(s.axes)}"]
    if model.boundary:
        lines += ["", "[boundary]"]
        lines += [f"{p} = {_toml_value([c for c, on in zip(_COMPONENTS, mask) if on])}"
                  for p, mask in model.boundary.items()]
    return "\n".join(lines) + "\n"
