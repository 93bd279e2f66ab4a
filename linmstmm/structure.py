"""The deduced transfer structure of a topology, in the papers' notation.

:func:`describe` turns a :class:`~linmstmm.topology.Topology` into a
:class:`StructureReport`: the root, the tips, the junctions, the multi-input
bodies with their inputs, the loop cuts, the order of Ū_all, and the block
layout of U_all as the automatic deduction theorem writes it
(Rui, Wang and Zhang's book, 2018, §11.4–11.6, and the
multiple launch rocket system study; ``docs/method.md``), so an engineer can compare the
deduction with a derivation by hand.

Block layout of ``U_all Z_all = 0``:

* block rows: the main transfer equation, then one geometric equation per
  non-first input k of every multi-input body j and one equation per joint j
  (a spring with released directions: no force along them), in
  ``topology.order``, as :class:`~linmstmm.deduction.Deduction` stacks them;
* block columns: the root state, then every tip and loop-cut state, then the
  jumps ``Δ[j]`` across every joint's released directions, in the order of
  ``Deduction.columns``;
* entries: ``-I`` (the root in the main row); ``T_{a-b}`` the product of the
  transfer matrices along the path from tip element a to root element b
  (``U_{j,Ik}`` where the path enters body j by input k ≥ 2); ``G_{a-j}`` the
  product along the path from tip element a up to, not including, body j,
  premultiplied by −H_j if the path enters j by its first input or by
  +H_{j,Ik} if it enters by input k; ``F_{a-j}`` the product from a up to
  joint j premultiplied by F_j (the forces along its released directions);
  a trailing ``E_j`` marks a path that starts at joint j's output with its
  jumps (``E_j Δ[j]``), and a trailing ``C`` the side of a
  loop cut written through the supplement equation ``Z_side1 = C Z_side0``;
  ``O`` where no path exists. Several paths sum: ``T_{a-b} + T_{c-b} C``.

The command ``linmstmm check`` prints the report and can draw the topology
figure (:mod:`linmstmm.plot_topology`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from linmstmm.deduction import Deduction
from linmstmm.model import COMPONENTS
from linmstmm.topology import Topology


@dataclass(frozen=True)
class End:
    """A boundary state vector of U_all: the root, a tip, or a closing cut as root.

    label : the boundary label (point name, ``"<rigid> free end"``) or
    ``"cut <point>"``. element : the element it feeds (tip) or leaves (root).
    fixed : fixed displacement components (``"x"`` … ``"rz"``).
    unknowns : the entries of its state vector kept in Z̄_all.
    """

    label: str
    element: str
    fixed: tuple[str, ...]
    unknowns: tuple[str, ...]


@dataclass(frozen=True)
class Input:
    """Input ``k`` (1 = first input) of a multi-input body at ``point``, fed by ``source``.

    source : the upstream element's name, or the state column ``Z[...]`` of a
    tip or cut feeding the body directly.
    """

    k: int
    point: str
    source: str


@dataclass(frozen=True)
class MultiInputBody:
    """A body with L ≥ 2 inputs: ``output`` point towards ``downstream``, inputs first input first."""

    name: str
    kind: str
    output: str
    downstream: str
    inputs: tuple[Input, ...]


@dataclass(frozen=True)
class LoopCut:
    """A cut connection point: side 0 enters (or, when closing, leaves) ``elements[0]``.

    supplement : the supplement equation in the papers' ``Z_{i,0}`` notation.
    closing : the cut that closes a model without any boundary end (its side
    0 is the root, ``C = I``). unknowns : the twelve entries of its state.
    """

    point: str
    elements: tuple[str, str]
    closing: bool
    supplement: str
    unknowns: tuple[str, ...]


@dataclass(frozen=True)
class Joint:
    """A spring with released directions: one jump unknown and one row of U_all each.

    name : the spring. released : its released directions (``"x"`` … ``"rz"``, its axes).
    """

    name: str
    released: tuple[str, ...]


@dataclass(frozen=True)
class Path:
    """The elements from the tip of ``column`` to the root element.

    A multi-input body is written ``name[Ik]``: entered by its input k.
    ``column`` ends in `` C`` for side 1 of a loop cut.
    """

    column: str
    elements: tuple[str, ...]


@dataclass(frozen=True)
class StructureReport:
    """The deduced structure of one topology (see the module docstring).

    blocks[r][c] is the entry of block row ``block_rows[r]`` and block column
    ``block_columns[c]``; the first row is ``"main"``, the others
    ``"<body> I<k>"``; the first column is the root's.
    """

    root: End
    tips: tuple[End, ...]
    junctions: tuple[str, ...]
    multi_input_bodies: tuple[MultiInputBody, ...]
    cuts: tuple[LoopCut, ...]
    joints: tuple[Joint, ...]
    paths: tuple[Path, ...]
    ubar_order: int
    block_rows: tuple[str, ...]
    block_columns: tuple[str, ...]
    blocks: tuple[tuple[str, ...], ...]

    def block(self, row: str, column: str) -> str:
        """The entry of block row ``row`` and block column ``column`` (labels)."""
        return self.blocks[self.block_rows.index(row)][self.block_columns.index(column)]

    def to_dict(self) -> dict:
        """Plain data (JSON-ready: strings, ints, bools, lists, dicts)."""
        return dataclasses.asdict(self)

    def to_text(self) -> str:
        """A readable summary and the block layout of U_all as an aligned table."""
        lines = [f"root: {_end_text(self.root)}", f"tips ({len(self.tips)}):"]
        lines += [f"  {_end_text(tip)}" for tip in self.tips]
        lines.append(f"junctions ({len(self.junctions)}): {', '.join(self.junctions) or '-'}")
        lines.append(f"multi-input bodies ({len(self.multi_input_bodies)}):")
        for body in self.multi_input_bodies:
            lines.append(f"  {body.name} ({body.kind}): output {body.output} -> {body.downstream}")
            lines += [f"    I{i.k} {i.point} <- {i.source}" + (" (first input)" if i.k == 1 else "")
                      for i in body.inputs]
        lines.append(f"loop cuts ({len(self.cuts)}):")
        lines += [f"  Z[cut {cut.point}] between {cut.elements[0]} and {cut.elements[1]}: "
                  f"{cut.supplement}" for cut in self.cuts]
        if self.joints:
            lines.append(f"joints ({len(self.joints)}):")
            lines += [f"  {joint.name}: released {' '.join(joint.released)}" for joint in self.joints]
        geometric = len(self.block_rows) - 1 - len(self.joints)
        released = sum(len(joint.released) for joint in self.joints)
        lines.append(f"order of Ubar_all: {self.ubar_order} "
                     f"(12 main rows + 6 x {geometric} geometric rows"
                     + (f" + {released} joint rows)" if released else ")"))
        lines.append("paths, tip -> root:")
        width = max((len(path.column) for path in self.paths), default=0)
        lines += [f"  {path.column:<{width}} : {' -> '.join(path.elements)}" for path in self.paths]
        lines.append("U_all Z_all = 0, block layout:")
        lines += ["  " + line for line in _table(self.block_rows, self.block_columns, self.blocks)]
        lines.append("unknowns kept in Zbar_all:")
        lines += [f"  {column}: {' '.join(unknowns)}"
                  for column, unknowns in zip(self.block_columns, self._unknowns())]
        lines += _LEGEND
        return "\n".join(lines)

    def _unknowns(self):
        """The unknowns of every block column, in column order."""
        ends = {_column(end.label): end.unknowns for end in (self.root, *self.tips)}
        ends |= {_column(f"cut {cut.point}"): cut.unknowns for cut in self.cuts}
        ends |= {_jump_column(joint.name): tuple(f"Δ{c}" for c in joint.released) for joint in self.joints}
        return [ends[column] for column in self.block_columns]


_LEGEND = (
    "legend: -I root state; T_{a-b} product of transfer matrices from tip element a to root",
    "  element b (U_{j,Ik} where the path enters body j by input k >= 2); G_{a-j} product from a",
    "  up to body j, premultiplied by -H_j (path into j's first input) or +H_{j,Ik} (into input k);",
    "  C = diag(I6, -I6) of a cut's supplement equation; O no path.",
    "  Joints: F_{a-j} product from a up to joint j, premultiplied by F_j (its released forces);",
    "  E_j the jumps of joint j entering at its output (a path from there, column Δ[j]).",
)


def describe(topology: Topology) -> StructureReport:
    """The deduced structure of ``topology``: ends, bodies, cuts, order and block layout."""
    deduction = Deduction(topology)
    unknowns = _unknowns_by_state(topology, deduction)
    elements = topology.elements
    states = [("boundary", b) for b in range(len(topology.boundaries))]
    states += [("cut", c) for c in range(len(topology.cuts))]
    joints = sorted(deduction.jump_columns)
    columns = [topology.root] + [state for state in states if state != topology.root]
    columns += [("jump", j) for j in joints]
    bodies = [e for e in topology.order if len(elements[e].inputs) >= 2]
    rows = [None] + [row for j in topology.order for row in (
        [(j, "joint")] if j in deduction.jump_columns else [(j, k) for k in range(1, len(elements[j].inputs))])]
    blocks, paths = _blocks(topology, rows, columns)
    return StructureReport(
        root=_root_end(topology, unknowns),
        tips=tuple(_tip_end(topology, b, unknowns) for b in range(len(topology.boundaries))
                   if ("boundary", b) != topology.root),
        junctions=tuple(el.name for el in elements if el.kind == "junction"),
        multi_input_bodies=tuple(_multi_input_body(topology, j) for j in bodies),
        cuts=tuple(_loop_cut(topology, c, unknowns) for c in range(len(topology.cuts))),
        joints=tuple(Joint(elements[j].name, tuple(COMPONENTS[d] for d in elements[j].record.released))
                     for j in joints),
        paths=paths,
        ubar_order=deduction.order,
        block_rows=tuple(_row_label(topology, row) for row in rows),
        block_columns=tuple(_jump_column(elements[state[1]].name) if state[0] == "jump"
                            else _column(_state_label(topology, state)) for state in columns),
        blocks=blocks,
    )


def _blocks(topology, rows, columns):
    """The block entries of U_all and the tip-to-root paths they come from.

    rows : None (main equation), (body, input index k ≥ 1) or (joint, "joint");
    columns : states, and ("jump", joint). Walks from every tip port (and every
    joint's output) to the root and writes a T term in the main row, a G term
    in every geometric row of each multi-input body passed and an F term in
    the row of each joint passed.
    """
    elements = topology.elements
    terms = {(r, c): [] for r in range(len(rows)) for c in range(len(columns))}
    terms[0, 0].append("-I")
    paths = []
    for state, factor, (e, p) in _tip_ports(topology):
        steps = _walk(topology, e, p)
        paths.append(Path(_column(_state_label(topology, state)) + factor,
                          tuple(_step_name(topology, step) for step in steps)))
        _write_path(topology, rows, terms, columns.index(state), elements[e].name, steps, factor)
    for c, (kind, j) in enumerate(columns):
        if kind == "jump":
            link = elements[j].ports[elements[j].output].link
            if link[0] == "element":
                _write_path(topology, rows, terms, c, elements[link[1]].name, _walk(topology, *link[1:]),
                            f" E_{{{elements[j].name}}}")
            else:  # the joint is the root element: its jumps enter the main row alone
                terms[0, c].append(f"E_{{{elements[j].name}}}")
    blocks = tuple(tuple(" + ".join(terms[r, c]) or "O" for c in range(len(columns)))
                   for r in range(len(rows)))
    return blocks, tuple(paths)


def _write_path(topology, rows, terms, c, tip, steps, factor):
    """The terms of one path from element ``tip`` along ``steps`` to the root, in column c."""
    elements = topology.elements
    terms[0, c].append(f"T_{{{tip}-{elements[topology.order[-1]].name}}}{factor}")
    for j, k in steps:
        for r in _geometric_rows(rows, j, k):
            terms[r, c].append(f"G_{{{tip}-{elements[j].name}}}{factor}")
        if (j, "joint") in rows:
            terms[rows.index((j, "joint")), c].append(f"F_{{{tip}-{elements[j].name}}}{factor}")


# --- walking the transfer tree ------------------------------------------------

def _tip_ports(topology):
    """(state, factor, (element, port)) of every port where a tip or cut state enters.

    factor is ``" C"`` for side 1 of an ordinary cut (``Z_side1 = C Z_side0``),
    else ``""``. The root side of a closing cut leaves the root element and is
    no tip.
    """
    where = {port.link: (e, p) for e, element in enumerate(topology.elements)
             for p, port in enumerate(element.ports)}
    for b in range(len(topology.boundaries)):
        if ("boundary", b) != topology.root:
            yield ("boundary", b), "", where["boundary", b]
    for c, cut in enumerate(topology.cuts):
        if not cut.closing:
            yield ("cut", c), "", where["cut", c, 0]
        yield ("cut", c), "" if cut.closing else " C", where["cut", c, 1]


def _walk(topology, e, p):
    """[(element, input index)] from element ``e`` entered by port ``p`` to the root element."""
    steps = []
    while True:
        element = topology.elements[e]
        steps.append((e, element.inputs.index(p)))
        link = element.ports[element.output].link
        if link[0] != "element":
            return steps
        _, e, p = link


def _geometric_rows(rows, j, k):
    """Block rows of body j that a path entering j by input index k takes part in.

    Input 1 (k = 0) appears in every geometric equation of j (−H_j), input
    k ≥ 2 only in its own (+H_{j,Ik}).
    """
    return [r for r, row in enumerate(rows) if row is not None and row[0] == j and row[1] != "joint"
            and (k == 0 or row[1] == k)]


def _step_name(topology, step):
    """An element on a path; a multi-input body carries the input it is entered by."""
    e, k = step
    element = topology.elements[e]
    return f"{element.name}[I{k + 1}]" if len(element.inputs) >= 2 else element.name


# --- labels and records ---------------------------------------------------------

def _column(label):
    """Block column heading of the state vector called ``label``."""
    return f"Z[{label}]"


def _jump_column(joint):
    """Block column heading of the jumps across joint ``joint``'s released directions."""
    return f"Δ[{joint}]"


def _row_label(topology, row):
    """Block row label: "main", "<body> I<k>" (geometric) or "<joint> free" (joint)."""
    if row is None:
        return "main"
    name = topology.elements[row[0]].name
    return f"{name} free" if row[1] == "joint" else f"{name} I{row[1] + 1}"


def _state_label(topology, state):
    """Label of a boundary end or loop cut state: its boundary label or ``cut <point>``."""
    kind, index = state
    if kind == "boundary":
        return topology.boundaries[index].label
    return f"cut {topology.cuts[index].point}"


def _unknowns_by_state(topology, deduction):
    """state -> names of its unknowns, read from ``deduction.columns``.

    Deduction lists six unknowns per boundary end, then twelve per cut, then
    the jumps of each joint, each labelled ``"<label>.<entry>"``.
    """
    labels = iter(deduction.columns)
    sizes = [(("boundary", b), 6) for b in range(len(topology.boundaries))]
    sizes += [(("cut", c), 12) for c in range(len(topology.cuts))]
    sizes += [(("jump", j), columns.size) for j, columns in sorted(deduction.jump_columns.items())]
    return {state: tuple(next(labels).rsplit(".", 1)[1] for _ in range(size))
            for state, size in sizes}


def _fixed(mask):
    return tuple(name for name, fixed in zip(COMPONENTS, mask) if fixed)


def _tip_end(topology, b, unknowns):
    """End record of boundary b, a tip."""
    boundary = topology.boundaries[b]
    where = next(element.name for element in topology.elements
                 for port in element.ports if port.link == ("boundary", b))
    return End(boundary.label, where, _fixed(boundary.fixed), unknowns["boundary", b])


def _root_end(topology, unknowns):
    """End record of the root: a boundary end, or the root side of a closing cut."""
    kind, index = topology.root
    fixed = _fixed(topology.boundaries[index].fixed) if kind == "boundary" else ()
    return End(_state_label(topology, topology.root), topology.elements[topology.order[-1]].name,
               fixed, unknowns[topology.root])


def _link_name(topology, link):
    """What a port is linked to: an element name or a state column."""
    if link[0] == "element":
        return topology.elements[link[1]].name
    return _column(_state_label(topology, link[:2]))


def _multi_input_body(topology, j):
    """MultiInputBody record of element j."""
    element = topology.elements[j]
    output = element.ports[element.output]
    inputs = tuple(Input(k, element.ports[p].point, _link_name(topology, element.ports[p].link))
                   for k, p in enumerate(element.inputs, start=1))
    return MultiInputBody(element.name, element.kind, output.point,
                          _link_name(topology, output.link), inputs)


def _loop_cut(topology, c, unknowns):
    """LoopCut record of cut c."""
    cut = topology.cuts[c]
    side0, side1 = (topology.elements[e].name for e, _ in cut.ends)
    if cut.closing:
        supplement = f"Z_{{{side1},0}} = Z_{{{side0},0}} (the root; C = I)"
    else:
        supplement = f"Z_{{{side1},0}} = C Z_{{{side0},0}}"
    return LoopCut(cut.point, (side0, side1), cut.closing, supplement, unknowns["cut", c])


def _end_text(end):
    fixed = " ".join(end.fixed) or "-"
    return (f"{end.label} (element {end.element}), fixed {fixed}; "
            f"unknowns {' '.join(end.unknowns)}")


def _table(rows, columns, blocks):
    """Lines of an aligned table with row labels ``rows`` and headings ``columns``."""
    cells = [["", *columns]] + [[row, *entries] for row, entries in zip(rows, blocks)]
    widths = [max(len(line[i]) for line in cells) for i in range(len(cells[0]))]
    return ["  ".join(cell.ljust(width) for cell, width in zip(line, widths)).rstrip()
            for line in cells]
