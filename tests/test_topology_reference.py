"""build_topology against a plain reference written from the rules of linmstmm.topology.

The order of the transfer elements, their ports' links, the boundary ends,
the cuts and the carry order decide the deduction (and so every result), so
they must be exactly these: element by element, point by point, breadth first
from the root in port order. Checked on the bundled models, random models of
every kind and varied models, with the default root, every other boundary end
as root, and forced cuts.
"""
from __future__ import annotations

from collections import deque

import numpy as np
import pytest
from builders import BUNDLED_MODELS
from random_models import KINDS, boundary_labels, loop_connections, random_model
from varied_models import varied_model

from linmstmm.builders import spring_chain
from linmstmm.model import load_model
from linmstmm.topology import build_topology


def reference(model, root=None, cut_at=()):
    """The topology as plain lists: elements (name, kind, [(point, link)], output, inputs),
    boundaries (label, fixed), cuts (point, ends, closing), root link, carry order."""
    ends = [list(r.ports if r.kind == "rigid" else r.ends) for r in model.elements]
    names = [r.name for r in model.elements]
    kinds = [r.kind for r in model.elements]
    links = [[None] * len(e) for e in ends]
    boundaries = []
    for e, points in enumerate(ends):
        if kinds[e] == "rigid" and len(points) == 1:
            points.append(f"{names[e]} free end")
            links[e].append(("boundary", len(boundaries)))
            boundaries.append((points[1], (False,) * 6))
    for point in model.points:
        here = [(e, p) for e in range(len(names)) for p in range(len(ends[e]))
                if ends[e][p] == point and links[e][p] is None]
        fixed = tuple(bool(f) for f in model.fixed_mask(point))
        if len(here) == 1:
            links[here[0][0]][here[0][1]] = ("boundary", len(boundaries))
            boundaries.append((point, fixed))
        elif len(here) == 2 and not any(fixed):
            (e, p), (f, q) = here
            links[e][p], links[f][q] = ("element", f, q), ("element", e, p)
        elif here:
            j = len(names)
            names.append(f"junction {point}")
            kinds.append("junction")
            ends.append([point] * (len(here) + any(fixed)))
            links.append([("element", e, p) for e, p in here])
            for k, (e, p) in enumerate(here):
                links[e][p] = ("element", j, k)
            if any(fixed):
                links[j].append(("boundary", len(boundaries)))
                boundaries.append((point, fixed))
    cuts = []

    def cut(a, b, closing=False):
        cuts.append((ends[a[0]][a[1]], (a, b), closing))
        links[a[0]][a[1]], links[b[0]][b[1]] = ("cut", len(cuts) - 1, 0), ("cut", len(cuts) - 1, 1)

    labels = [label for label, _ in boundaries]
    if root is not None:
        b = labels.index(root)
    else:
        b = max(range(len(boundaries)), key=lambda i: (sum(boundaries[i][1]), -i)) if boundaries else None
    for point in cut_at[1 if b is None else 0:]:
        cut(*[(e, p) for e in range(len(names)) for p in range(len(ends[e]))
              if ends[e][p] == point and links[e][p][0] == "element"])
    ports = [(e, p) for e in range(len(names)) for p in range(len(ends[e]))]
    if b is None:
        start = next((e, p) for e, p in ports if links[e][p][0] == "element" and (not cut_at or ends[e][p] == cut_at[0]))
        cut(start, links[start[0]][start[1]][1:], closing=True)
        root_link = ("cut", len(cuts) - 1)
    else:
        start = next((e, p) for e, p in ports if links[e][p] == ("boundary", b))
        root_link = ("boundary", b)
    outputs, inputs = {start[0]: start[1]}, {}
    order, queue = [], deque([start[0]])
    while queue:
        e = queue.popleft()
        order.append(e)
        inputs[e] = [p for p in range(len(ends[e])) if p != outputs[e]]
        for p in inputs[e]:
            if links[e][p][0] == "element":
                _, f, q = links[e][p]
                if f in outputs:
                    cut((e, p), (f, q))
                else:
                    outputs[f] = q
                    queue.append(f)
    elements = [(names[e], kinds[e], list(zip(ends[e], links[e])), outputs[e], inputs[e]) for e in range(len(names))]
    return elements, boundaries, cuts, root_link, order[::-1]


def described(topology):
    """The same lists read off a Topology (positions checked apart)."""
    elements = [(el.name, el.kind, [(port.point, port.link) for port in el.ports], el.output, el.inputs)
                for el in topology.elements]
    boundaries = [(b.label, tuple(bool(f) for f in b.fixed)) for b in topology.boundaries]
    cuts = [(c.point, c.ends, c.closing) for c in topology.cuts]
    return elements, boundaries, cuts, topology.root, topology.order


def positions_agree(model, topology) -> bool:
    """Every port sits at its point (a free far side at its body's port)."""
    return all(np.array_equal(port.position, model.points[port.point if port.point in model.points
                                                          else el.ports[0].point])
               for el in topology.elements for port in el.ports)


MODELS = ([load_model(path) for path in BUNDLED_MODELS] + [spring_chain(12)]
          + [random_model(kind, seed) for kind in KINDS for seed in range(12)]
          + [varied_model(seed)[0] for seed in range(40)])


@pytest.mark.parametrize("model", MODELS, ids=lambda model: model.name)
def test_topology_is_the_plain_reference(model):
    variants = [{}] + [dict(root=label) for label in boundary_labels(model)[:4]] \
        + [dict(cut_at=(point,)) for point in loop_connections(model)[:3]]
    for variant in variants:
        topology = build_topology(model, **variant)
        assert described(topology) == reference(model, **variant), variant
        assert positions_agree(model, topology)
