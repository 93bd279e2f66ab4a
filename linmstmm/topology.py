"""Topology of a model for the automatic deduction theorem.

From the model records this module finds the transfer elements (every
element, plus one massless rigid *junction* body at each point where three or
more element ends meet, or two ends and a boundary condition), the boundary
ends (points with one element end, and the free far side of every one-port
rigid body), picks the root boundary, directs transfer from the tips to the
root along a spanning tree, picks each multi-input body's first input, and
cuts every closed loop. A cut makes two new boundary ends whose states are
tied by a supplement equation: equal displacements, opposite forces.

A model with no boundary end at all (a free ring) is closed at one
connection point instead: that point's state leaves the last element as the
root state and enters the first as a tip state, and the two are equal.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from linmstmm.collector import collector_paused
from linmstmm.model import Model, ModelError


@dataclass(frozen=True)
class Boundary:
    """A boundary end: where a transfer element meets the ground or nothing.

    label : name shown to users (point name, ``"<rigid> free end"``, ...).
    position : (3,) m. fixed : (6,) bool, fixed displacement components.
    """

    label: str
    position: np.ndarray
    fixed: np.ndarray


@dataclass(slots=True)
class Port:
    """One end of a transfer element.

    point : point name. position : (3,) m.
    link : ``("element", e, p)`` to port p of element e, ``("boundary", b)``,
    or ``("cut", c, side)`` after loop cutting (side 0 or 1 of cut c).
    """

    point: str
    position: np.ndarray
    link: tuple = ()


@dataclass(slots=True)
class TransferElement:
    """An element in the transfer graph (a model element or a junction).

    record : the model record (``None`` for a junction). output : index of the
    port towards the root; inputs : the other ports, first input first.
    """

    name: str
    kind: str
    record: object
    ports: list[Port]
    output: int = -1
    inputs: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class Cut:
    """A cut connection point: two new tips, ``Z_side1 = C Z_side0``.

    ends : ((element, port), (element, port)). closing : True for the cut of a
    boundary-less model, where side 0 is the root and ``C = I``.
    """

    point: str
    ends: tuple
    closing: bool = False


@dataclass
class Topology:
    """Directed spanning tree of transfer elements, tips to root.

    order : element indices, every element after all elements upstream of it.
    root : ``("boundary", b)`` or ``("cut", c)`` for a closing cut.
    """

    elements: list[TransferElement]
    boundaries: list[Boundary]
    cuts: list[Cut]
    root: tuple
    order: list[int]

    @property
    def root_label(self) -> str:
        kind, index = self.root
        return self.boundaries[index].label if kind == "boundary" else self.cuts[index].point


def _model_elements(model: Model) -> tuple[list[TransferElement], dict[str, list[tuple[int, int]]]]:
    """Transfer elements for the model's own elements, with their ports, and the
    (element, port) ends at each point (a tip body's free far side at none)."""
    points = model.points
    at_point: dict[str, list[tuple[int, int]]] = {p: [] for p in points}
    elements = []
    for e, record in enumerate(model.elements):
        names = record.ports if record.kind == "rigid" else record.ends
        ports = []
        for p, name in enumerate(names):
            ports.append(Port(name, points[name]))
            at_point[name].append((e, p))
        if len(ports) == 1:  # a tip body: its far side is a free boundary end
            ports.append(Port(f"{record.name} free end", points[names[0]], ("free-end",)))
        elements.append(TransferElement(record.name, record.kind, record, ports))
    return elements, at_point


def _link_points(model: Model, elements: list[TransferElement], at_point: dict) -> tuple[list[Boundary], list]:
    """Connect ports at shared points (``at_point``: point -> its (element, port) ends),
    add junctions; return the boundary ends and the (element, port) linked to each."""
    boundaries: list[Boundary] = []
    ends_of: list[tuple[int, int]] = []  # the port linked to each boundary end

    def bound(e, p, label, position, fixed):
        elements[e].ports[p].link = ("boundary", len(boundaries))
        boundaries.append(Boundary(label, position, fixed))
        ends_of.append((e, p))

    for e, element in enumerate(elements):
        if element.kind == "rigid" and element.ports[-1].link:  # ("free-end",)
            bound(e, len(element.ports) - 1, element.ports[-1].point, element.ports[-1].position,
                  np.zeros(6, dtype=bool))
    held = {point for point, mask in model.boundary.items() if mask.any()}  # points with a fixed component
    for point, ends in at_point.items():
        if len(ends) == 1:
            bound(*ends[0], point, model.points[point], model.fixed_mask(point))
        elif len(ends) == 2 and point not in held:
            (e, p), (f, q) = ends
            elements[e].ports[p].link = ("element", f, q)
            elements[f].ports[q].link = ("element", e, p)
        elif ends:
            junction = TransferElement(f"junction {point}", "junction", None, [])
            j = len(elements)
            elements.append(junction)
            for e, p in ends:
                elements[e].ports[p].link = ("element", j, len(junction.ports))
                junction.ports.append(Port(point, model.points[point], ("element", e, p)))
            if point in held:
                junction.ports.append(Port(point, model.points[point]))
                bound(j, len(junction.ports) - 1, point, model.points[point], model.fixed_mask(point))
    return boundaries, ends_of


def _choose_root(model, elements, boundaries, root_point):
    """The root boundary index: ``root_point`` if given, else the most constrained end."""
    if root_point is not None:
        for b, boundary in enumerate(boundaries):
            if boundary.label == root_point:
                return b
        names = ", ".join(repr(b.label) for b in boundaries) or "none"
        raise ModelError(model.source or model.name, f"'{root_point}' is not a boundary end "
                         f"(boundary ends: {names})", key="root")
    if not boundaries:
        return None
    return max(range(len(boundaries)), key=lambda b: (np.count_nonzero(boundaries[b].fixed), -b))


def _grow_tree(elements, start, cuts):
    """Breadth-first spanning tree from element ``start`` (its output already set).

    Sets every reached element's output and inputs, turns every non-tree
    connection into a cut. Returns the visiting order (root element first).
    """
    visited = [False] * len(elements)
    visited[start] = True
    order = [start]
    for e in order:  # the list grows as it is read: the queue
        element = elements[e]
        ports, output = element.ports, element.output
        element.inputs = [1 - output] if len(ports) == 2 else [p for p in range(len(ports)) if p != output]
        for p in element.inputs:
            link = ports[p].link
            if link[0] != "element":
                continue
            _, f, q = link
            if visited[f]:  # a second path to f: close the loop by a cut here
                c = len(cuts)
                cuts.append(Cut(ports[p].point, ((e, p), (f, q))))
                ports[p].link = ("cut", c, 0)
                elements[f].ports[q].link = ("cut", c, 1)
            else:
                visited[f] = True
                elements[f].output = q
                order.append(f)
    return order


def _cut_connections(model, elements, points, cuts):
    """Cut the two-element connections at ``points`` before the tree is grown."""
    for point in points:
        ends = [(e, p) for e, el in enumerate(elements) for p, port in enumerate(el.ports)
                if port.point == point and port.link[0] == "element"]
        if len(ends) != 2 or elements[ends[0][0]].kind == "junction" or elements[ends[1][0]].kind == "junction":
            raise ModelError(model.source or model.name,
                             f"'{point}' is not a connection of exactly two elements", key="cut")
        c = len(cuts)
        cuts.append(Cut(point, tuple(ends)))
        for side, (e, p) in enumerate(ends):
            elements[e].ports[p].link = ("cut", c, side)


@collector_paused()
def build_topology(model: Model, root: str | None = None, cut_at=()) -> Topology:
    """Deduce the directed transfer structure of ``model``.

    root : boundary end label (point name) to use as the root; default: the
    end with the most fixed components, first in file order among equals.
    cut_at : connection points to cut first (loops not cut there are cut
    where the spanning tree closes them); in a model with no boundary end
    the first of them is where the structure is closed.
    """
    elements, at_point = _model_elements(model)
    boundaries, ends_of = _link_points(model, elements, at_point)
    cuts: list[Cut] = []
    b = _choose_root(model, elements, boundaries, root)
    closing_point = cut_at[0] if (b is None and cut_at) else None
    _cut_connections(model, elements, [p for p in cut_at if p != closing_point], cuts)
    if b is not None:
        start, port = ends_of[b]
        root_link = ("boundary", b)
    else:  # no boundary at all: close the structure at cut_at[0], else its first connection
        start, port = next((e, p) for e, el in enumerate(elements)
                           for p, pt in enumerate(el.ports) if pt.link[0] == "element"
                           and closing_point in (None, pt.point))
        _, f, q = elements[start].ports[port].link
        c = len(cuts)
        cuts.append(Cut(elements[start].ports[port].point, ((start, port), (f, q)), closing=True))
        elements[start].ports[port].link = ("cut", c, 0)
        elements[f].ports[q].link = ("cut", c, 1)
        root_link = ("cut", c)
    elements[start].output = port
    order = _grow_tree(elements, start, cuts)
    reached = set(order)
    unreached = [el.name for e, el in enumerate(elements) if e not in reached]
    if unreached:
        raise ModelError(model.source or model.name,
                         f"the model is not connected: {', '.join(unreached)} "
                         f"cannot be reached from {elements[start].name}")
    return Topology(elements, boundaries, cuts, root_link, order[::-1])
