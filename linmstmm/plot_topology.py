"""The topology figure of a model, in the convention of the topology
figures of Rui, Wang and Zhang's book (2018), §11.2 (``docs/method.md``).

* a body is a circle with its name: rigid bodies white, beams light blue
  (a beam is a body element here, drawn as a circle too), junctions (the
  massless rigid bodies at points where three or more ends meet) small and
  grey, named by their point;
* a hinge (spring) is a thick arrow in the transfer direction, from the
  spring's place in the figure to the element it feeds, labelled with the
  spring's name beside its start, on the side the arrow does not take; every other connection is a thin grey line, with a small
  head in the transfer direction where it reaches a body or boundary end;
* a boundary end is a boxed ``0`` with its label, the root marked ``root``;
* a loop cut gives two new boundary ends, drawn as red ``0`` and joined by a
  dashed red arc labelled with the supplement matrix ``C`` (``C = I`` for the
  cut that closes a model without boundary ends, one side being the root);
* the inputs of a multi-input body are labelled ``I1``, ``I2``, … next to it;
* a legend below the figure keys every symbol the figure uses.

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
from matplotlib.lines import Line2D

from linmstmm.label_layout import line_samples, place_label
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
    topology_figure(topology, title).savefig(path, format="png", dpi=130, bbox_inches="tight")


def topology_figure(topology: Topology, title: str | None = None) -> Figure:
    """The figure :func:`plot_topology` writes, with its legend, not yet saved."""
    children = _children(topology)
    position = _layout(topology, children)
    arcs = [_cut_arc(position[("cut", c, 0)], position[("cut", c, 1)])
            for c in range(len(topology.cuts))]
    figure, axes = _canvas(np.vstack([*position.values(), *arcs]), title)
    arc_sides = {("cut", c, side): np.sign(arc[-2 if side else 1, 1] - arc[-1 if side else 0, 1])
                 for c, arc in enumerate(arcs) for side in (0, 1)}
    patches = {node: _draw_node(axes, topology, node, position[node], arc_sides.get(node, 0.0))
               for node in position}
    lines = [*arcs]
    for node, inputs in children.items():
        for k, child in enumerate(inputs):
            _draw_connection(axes, topology, child, node, position, patches)
            lines.append(np.array([position[child], position[node]], dtype=float))
            if len(inputs) >= 2:
                _label_input(axes, position[node], position[child], k)
    for cut, arc in zip(topology.cuts, arcs):
        _draw_cut_arc(axes, arc, "C = I" if cut.closing else "C")
    springs = [(element.name, position[("element", e)]) for e, element in enumerate(topology.elements)
               if element.kind == "spring" and ("element", e) in position]
    _name_springs(figure, axes, springs, lines)
    _legend(figure, topology)
    return figure


def _canvas(extent, title):
    """An Agg figure and bare axes sized to the (n, 2) points ``extent``, y downwards."""
    low, high = extent.min(axis=0), extent.max(axis=0)
    width, height = high - low
    figure = Figure(figsize=(max(6.0, 1.2 * width + 2.0), max(3.5, 0.75 * height + 2.6)))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    axes.set_axis_off()
    axes.set_xlim(low[0] - 0.7, high[0] + 0.7)
    axes.set_ylim(high[1] + 0.6, low[1] - 0.8)
    if title:
        axes.set_title(title)
    return figure, axes


def _legend(figure, topology) -> None:
    """The key below the figure: the element kinds and symbols this figure uses."""
    kinds = {element.kind for element in topology.elements}

    def body(kind, label):
        style = _BODY_STYLE[kind]
        return Line2D([], [], ls="", marker="o", markersize=9 if kind != "junction" else 6,
                      markerfacecolor=style["facecolor"], markeredgecolor=style["edgecolor"], label=label)
    handles = [body(kind, label) for kind, label in (
        ("rigid", "rigid body"), ("beam", "beam (a body element)"),
        ("junction", "junction: massless body where 3+ ends meet, named by its point")) if kind in kinds]
    if "spring" in kinds:
        handles.append(Line2D([], [], color="black", lw=2.2, marker=">", markevery=[1],
                              label="elastic hinge (spring), transfer direction"))
    handles += [Line2D([], [], color="grey", lw=1.0, marker=">", markersize=4, markevery=[1],
                       label="connection, transfer direction"),
                Line2D([], [], ls="", marker="s", markersize=9, markerfacecolor="white",
                       markeredgecolor="black", label="boundary end (0), root marked 'root'")]
    if topology.cuts:
        handles.append(Line2D([], [], color=_CUT_COLOR, ls="--", marker="s", markersize=7,
                              markerfacecolor="white", markevery=[0],
                              label="loop cut: its two new ends; C supplements the cut"))
    if any(len(element.inputs) >= 2 for element in topology.elements):
        handles.append(Line2D([], [], ls="", marker="$I1$", markersize=10, color="tab:blue",
                              label="inputs of a multi-input body, first to last"))
    for handle in handles:
        if handle.get_linestyle() not in ("None", ""):
            handle.set_data([0, 1], [0, 0])
    figure.legend(handles=handles, loc="lower center", ncols=min(3, len(handles)), fontsize=8,
                  frameon=False, bbox_to_anchor=(0.5, -0.02))


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

def _draw_node(axes, topology, node, xy, arc_side=0.0):
    """Draw one node; return the outline arrows stop at (None for a spring).

    arc_side : for a cut's end, +1 when its dashed arc leaves downwards
    (the label then goes above), −1 upwards, 0 for other nodes.
    """
    if node[0] == "element":
        return _draw_element(axes, topology.elements[node[1]], xy)
    label = (topology.boundaries[node[1]].label if node[0] == "boundary"
             else f"cut {topology.cuts[node[1]].point}")
    if node == _root_node(topology):
        label = f"root: {label}"
    return _draw_end(axes, label, xy, _CUT_COLOR if node[0] == "cut" else "black", above=arc_side > 0)


def _draw_element(axes, element, xy):
    """A body as a named circle (outline returned); nothing for a spring (None).

    A spring is named once everything else is drawn (:func:`_name_springs`).
    """
    if element.kind == "spring":
        return None
    name = element.ports[0].point if element.kind == "junction" else element.name
    text = axes.text(*xy, name, ha="center", va="center", fontsize=8,
                     bbox=_BODY_STYLE[element.kind], zorder=3)
    return text.get_bbox_patch()


def _draw_end(axes, label, xy, color, above=False):
    """A boundary end: a boxed 0 with ``label`` below (or above); returns the box."""
    axes.annotate(label, xy, xytext=(0, 11 if above else -11), textcoords="offset points", ha="center",
                  va="bottom" if above else "top", fontsize=7, color=color)
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


def _name_springs(figure, axes, springs, lines) -> None:
    """Write each spring's name at the first place around it that is clear.

    Clear: the name's box meets no text or node outline drawn so far and no
    connection or cut arc (``lines``: (k, 2) polylines, data coordinates);
    see :func:`linmstmm.label_layout.place_label`.
    """
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    taken = [(text.get_bbox_patch() or text).get_window_extent(renderer) for text in axes.texts]
    samples = line_samples(axes, lines)
    for name, xy in springs:
        place_label(axes, name, xy, samples, taken, fontsize=8)


def _label_input(axes, body_xy, input_xy, k):
    """``I<k+1>`` on the connection from input k to the body, over the line, near the body."""
    x, y = np.add(body_xy, 0.45 * np.subtract(input_xy, body_xy))
    axes.text(x, y, f"I{k + 1}", ha="center", va="center", fontsize=7, color="tab:blue", zorder=5,
              bbox=dict(boxstyle="round,pad=0.1", facecolor="white", edgecolor="none"))


def _draw_cut_arc(axes, arc, label):
    """The dashed arc joining the two boundary ends of a cut, labelled by its supplement matrix."""
    axes.plot(*arc.T, linestyle="--", lw=1.0, color=_CUT_COLOR, zorder=1)
    axes.text(*arc[len(arc) // 2], label, color=_CUT_COLOR, fontsize=8, ha="center", va="center", zorder=5,
              bbox=dict(boxstyle="square,pad=0.1", facecolor="white", edgecolor="none"))


def _cut_arc(side0, side1):
    """(21, 2) points of a quadratic Bézier arc from one side of a cut to the other."""
    a, b = np.asarray(side0, float), np.asarray(side1, float)
    control = (a + b) / 2 + 0.6 * np.array([b[1] - a[1], a[0] - b[0]])
    t = np.linspace(0.0, 1.0, 21)[:, None]
    return (1 - t) ** 2 * a + 2 * t * (1 - t) * control + t ** 2 * b
