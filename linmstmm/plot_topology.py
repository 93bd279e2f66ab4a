"""The topology figure of a model, in the convention of the topology
figures of Rui, Wang and Zhang's book (2018), §11.2 (``docs/method.md``).

* a body is a circle with its name: rigid bodies white, beams light blue
  (a beam is a body element here, drawn as a circle too), junctions (the
  massless rigid bodies at points where three or more ends meet) small and
  grey, named by their point;
* a hinge (spring) is a thick arrow in the transfer direction, from the
  spring's place in the figure to the element it feeds, labelled with the
  spring's name; every other connection is a thin grey line, with a small
  head in the transfer direction where it reaches a body or boundary end;
* a boundary end is a boxed ``0`` with its label, the root marked ``root``;
* a loop cut gives two new boundary ends, drawn as red ``0`` and joined by a
  dashed red arc labelled with the supplement matrix ``C`` (``C = I`` for the
  cut that closes a model without boundary ends, one side being the root);
* the inputs of a multi-input body are labelled ``I1``, ``I2``, … next to it.

Layout: layers by depth from the root (root on the right, tips to the left,
so transfer runs left to right as in the book's figures); the tips of the
transfer tree are stacked in depth-first order and every element sits at the
mean height of its inputs. The figure is drawn with the Agg backend into a
PNG file; no window is opened.
"""
from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from linmstmm.topology import Topology

_BODY_STYLE = {
    "rigid": dict(boxstyle="circle,pad=0.35", facecolor="white", edgecolor="black"),
    "beam": dict(boxstyle="circle,pad=0.35", facecolor="#cfe3f7", edgecolor="black"),
    "junction": dict(boxstyle="circle,pad=0.2", facecolor="#d9d9d9", edgecolor="grey"),
}
_END_STYLE = dict(boxstyle="square,pad=0.25", facecolor="white")
_CUT_COLOR = "tab:red"


def plot_topology(topology: Topology, path, title: str | None = None) -> None:
    """Write the topology figure of ``topology`` to ``path`` as a PNG file.

    title : optional heading (e.g. the model name).
    """
    children = _children(topology)
    position = _layout(topology, children)
    arcs = [_cut_arc(position[("cut", c, 0)], position[("cut", c, 1)])
            for c in range(len(topology.cuts))]
    figure, axes = _canvas(np.vstack([*position.values(), *arcs]), title)
    patches = {node: _draw_node(axes, topology, node, position[node]) for node in position}
    for node, inputs in children.items():
        for k, child in enumerate(inputs):
            _draw_connection(axes, topology, child, node, position, patches)
            if len(inputs) >= 2:
                _label_input(axes, position[node], position[child], k)
    for cut, arc in zip(topology.cuts, arcs):
        _draw_cut_arc(axes, arc, "C = I" if cut.closing else "C")
    figure.savefig(path, format="png", dpi=130, bbox_inches="tight")


def _canvas(extent, title):
    """An Agg figure and bare axes sized to the (n, 2) points ``extent``, y downwards."""
    low, high = extent.min(axis=0), extent.max(axis=0)
    width, height = high - low
    figure = Figure(figsize=(max(4.0, 1.2 * width + 2.0), max(2.5, 0.75 * height + 1.8)))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    axes.set_axis_off()
    axes.set_xlim(low[0] - 0.7, high[0] + 0.7)
    axes.set_ylim(high[1] + 0.6, low[1] - 0.8)
    if title:
        axes.set_title(title)
    return figure, axes


# --- the transfer tree ----------------------------------------------------------

def _root_node(topology):
    """The root's node: a boundary end, or side 0 of the closing cut."""
    kind, index = topology.root
    return ("boundary", index) if kind == "boundary" else ("cut", index, 0)


def _children(topology):
    """node -> the nodes feeding it, first input first.

    Nodes: ``("element", e)``, ``("boundary", b)``, ``("cut", c, side)``.
    """
    children = {_root_node(topology): [("element", topology.order[-1])]}
    for e in topology.order:
        element = topology.elements[e]
        links = [element.ports[p].link for p in element.inputs]
        children[("element", e)] = [("element", link[1]) if link[0] == "element" else link
                                    for link in links]
    return children


def _layout(topology, children):
    """node -> (x, y): x = −depth from the root, tips stacked in depth-first order."""
    root = _root_node(topology)
    depth = {root: 0}
    leaves = []
    stack = [root]
    while stack:
        node = stack.pop()
        inputs = children.get(node, [])
        if not inputs:
            leaves.append(node)
        for child in inputs:
            depth[child] = depth[node] + 1
        stack.extend(reversed(inputs))
    height = {leaf: float(y) for y, leaf in enumerate(leaves)}
    for e in topology.order:
        height[("element", e)] = float(np.mean([height[c] for c in children[("element", e)]]))
    height[root] = height[("element", topology.order[-1])]
    return {node: (-depth[node], height[node]) for node in depth}


# --- drawing ------------------------------------------------------------------------

def _draw_node(axes, topology, node, xy):
    """Draw one node; return the outline arrows stop at (None for a spring)."""
    if node[0] == "element":
        return _draw_element(axes, topology.elements[node[1]], xy)
    label = (topology.boundaries[node[1]].label if node[0] == "boundary"
             else f"cut {topology.cuts[node[1]].point}")
    if node == _root_node(topology):
        label = f"root: {label}"
    return _draw_end(axes, label, xy, _CUT_COLOR if node[0] == "cut" else "black")


def _draw_element(axes, element, xy):
    """A body as a named circle (outline returned); a spring's name only (None)."""
    if element.kind == "spring":
        axes.annotate(element.name, xy, xytext=(0, 7), textcoords="offset points",
                      ha="center", va="bottom", fontsize=8)
        return None
    name = element.ports[0].point if element.kind == "junction" else element.name
    text = axes.text(*xy, name, ha="center", va="center", fontsize=8,
                     bbox=_BODY_STYLE[element.kind], zorder=3)
    return text.get_bbox_patch()


def _draw_end(axes, label, xy, color):
    """A boundary end: a boxed 0 with ``label`` below; returns the box."""
    axes.annotate(label, xy, xytext=(0, -11), textcoords="offset points", ha="center",
                  va="top", fontsize=7, color=color)
    text = axes.text(*xy, "0", ha="center", va="center", fontsize=9, fontweight="bold",
                     color=color, bbox=_END_STYLE | {"edgecolor": color}, zorder=3)
    return text.get_bbox_patch()


def _draw_connection(axes, topology, child, node, position, patches):
    """The connection from ``child`` to the node it feeds.

    A spring is a thick arrow; any other connection a thin grey line, with a
    small head where it reaches a body or boundary (not a spring's place).
    Drawn above the nodes: the nodes' outlines, which clip the arrow, are
    placed only when the nodes are drawn.
    """
    if child[0] == "element" and topology.elements[child[1]].kind == "spring":
        style = dict(arrowstyle="-|>,head_length=1.0,head_width=0.45", lw=2.2, color="black")
    elif patches[node] is not None:
        style = dict(arrowstyle="-|>,head_length=0.6,head_width=0.25", lw=1.0, color="grey")
    else:
        style = dict(arrowstyle="-", lw=1.0, color="grey")
    axes.annotate("", xy=position[node], xytext=position[child], zorder=4,
                  arrowprops=style | dict(patchA=patches[child], patchB=patches[node],
                                          shrinkA=0, shrinkB=0, mutation_scale=12))


def _label_input(axes, body_xy, input_xy, k):
    """``I<k+1>`` next to body, on the connection to its input k."""
    x, y = np.add(body_xy, 0.4 * np.subtract(input_xy, body_xy))
    axes.text(x, y - 0.12, f"I{k + 1}", ha="center", va="bottom", fontsize=7, color="tab:blue")


def _draw_cut_arc(axes, arc, label):
    """The dashed arc joining the two boundary ends of a cut, labelled by its supplement matrix."""
    axes.plot(*arc.T, linestyle="--", lw=1.0, color=_CUT_COLOR, zorder=1)
    axes.text(*arc[len(arc) // 2], label, color=_CUT_COLOR, fontsize=8, ha="center", va="center",
              bbox=dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none"))


def _cut_arc(side0, side1):
    """(21, 2) points of a quadratic Bézier arc from one side of a cut to the other."""
    a, b = np.asarray(side0, float), np.asarray(side1, float)
    control = (a + b) / 2 + 0.6 * np.array([b[1] - a[1], a[0] - b[0]])
    t = np.linspace(0.0, 1.0, 21)[:, None]
    return (1 - t) ** 2 * a + 2 * t * (1 - t) * control + t ** 2 * b
