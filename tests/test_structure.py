"""The deduced structure (``linmstmm.structure``) and the topology figure.

The block layouts below are written by hand from the theorem (Rui, Wang and
Zhang's book, 2018, §11.4–11.6; docs/method.md) for each topology and compared
entry by entry.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from builders import fixed, make_rigid, make_spring

from linmstmm import cli
from linmstmm.deduction import Deduction
from linmstmm.model import Model, load_model
from linmstmm.plot_topology import plot_topology, topology_figure
from linmstmm.structure import describe
from linmstmm.topology import build_topology

ROOT = Path(__file__).resolve().parents[1]
CHAIN = str(ROOT / "models" / "spring_mass_chain.toml")
K = [1e4, 2e4, 3e4, 1e3, 2e3, 3e3]
FIXED_UNKNOWNS = ("Qx", "Qy", "Qz", "Mx", "My", "Mz")
FREE_UNKNOWNS = ("X", "Y", "Z", "Θx", "Θy", "Θz")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def spring_body_model(bodies, springs, ground=None):
    """Model from ``bodies`` {name: ports} and ``springs`` {name: (a, b, position)}.

    Each spring joins points a and b at ``position``; a body's mass centre is
    the mean of its ports; ``ground`` is the fixed point (None: no boundary).
    """
    points = {}
    for a, b, xy in springs.values():
        points[a] = points[b] = np.array([*xy, 0.0])
    rigids = tuple(make_rigid(name, ports, 2.0, np.mean([points[p] for p in ports], axis=0),
                              (0.1, 0.2, 0.3)) for name, ports in bodies.items())
    return Model("springs and bodies", points, rigids=rigids,
                 springs=tuple(make_spring(name, a, b, K) for name, (a, b, _) in springs.items()),
                 boundary={} if ground is None else {ground: fixed()})


def book_figure_11_1():
    """The tree of the book's Figure 11.1: elements numbered as in the book.

    Tip bodies 1–4 feed bodies 9 (by hinges 5, 6) and 10 (by 7, 8); 9 feeds
    body 13 by hinge 11, 13 feeds body 15 by hinge 14 (its first input P15,14),
    10 feeds 15 by hinge 12 (second input P15,12); 15 → hinge 16 → body 17 →
    hinge 18 → the root boundary z18,0. First inputs: P9,5, P10,7, P15,14.
    """
    bodies = {"1": ["a5"], "2": ["a6"], "3": ["a7"], "4": ["a8"],
              "9": ["b5", "b6", "a11"], "10": ["b7", "b8", "a12"], "13": ["b11", "a14"],
              "15": ["b14", "b12", "a16"], "17": ["b16", "a18"]}
    springs = {"5": ("a5", "b5", (1, 3)), "6": ("a6", "b6", (1, 2)),
               "7": ("a7", "b7", (1, 1)), "8": ("a8", "b8", (1, 0)),
               "11": ("a11", "b11", (2, 2.5)), "14": ("a14", "b14", (3, 2)),
               "12": ("a12", "b12", (3, 0.5)), "16": ("a16", "b16", (4, 1)),
               "18": ("a18", "g", (5, 1))}
    return spring_body_model(bodies, springs, "g")


def loop_model():
    """Ground –k0– body R1; R1 –s1– R2 and R1 –s2– R2 close a loop.

    The breadth-first spanning tree reaches R2 through s1 (R1's first input)
    and closes the loop when it reaches s2, so the cut is at q2: side 0
    enters s2, side 1 enters R2.
    """
    bodies = {"R1": ["b0", "p1", "p2"], "R2": ["q1", "q2"]}
    springs = {"k0": ("g", "b0", (0, 0)), "s1": ("p1", "q1", (1, 1)),
               "s2": ("p2", "q2", (1, -1))}
    return spring_body_model(bodies, springs, "g")


def ring_model():
    """The book's Figure 11.7: three masses and three springs in a ring, no boundary."""
    bodies = {"m1": ["a1", "b1"], "m2": ["a2", "b2"], "m3": ["a3", "b3"]}
    springs = {"k1": ("b1", "a2", (1, 0)), "k2": ("b2", "a3", (0, 1)),
               "k3": ("b3", "a1", (-1, 0))}
    return spring_body_model(bodies, springs)


def chain_model():
    """Ground –k1– m1 –k2– m2 with a free tip: a chain."""
    return spring_body_model({"m1": ["a1", "b1"], "m2": ["a2"]},
                      {"k1": ("g", "a1", (0, 0)), "k2": ("b1", "a2", (1, 0))}, "g")


def junction_model():
    """Three springs meet at point j (a junction): k0 to the fixed ground, k1, k2 to tip bodies."""
    return spring_body_model({"m1": ["p1"], "m2": ["p2"]},
                             {"k0": ("g", "j", (0, 0)), "k1": ("p1", "j", (0, 0)),
                              "k2": ("p2", "j", (0, 0))}, "g")


def test_chain_has_one_t_block_and_minus_identity():
    report = describe(build_topology(chain_model()))
    assert report.block_rows == ("main",)
    assert report.block_columns == ("Z[g]", "Z[m2 free end]")
    assert report.blocks == (("-I", "T_{m2-k1}"),)
    assert report.root.fixed == ("x", "y", "z", "rx", "ry", "rz")
    assert report.root.unknowns == FIXED_UNKNOWNS
    assert [tip.unknowns for tip in report.tips] == [FREE_UNKNOWNS]
    assert report.ubar_order == 12 and not report.cuts and not report.multi_input_bodies
    assert report.paths[0].elements == ("m2", "k2", "m1", "k1")


def test_tree_with_one_multi_input_body_has_its_geometric_row():
    bodies = {"base": ["b0", "b1", "b2", "b3"], "t1": ["c1"], "t2": ["c2"], "t3": ["c3"]}
    springs = {"k0": ("g", "b0", (0, 0)), "k1": ("c1", "b1", (1, 1)),
               "k2": ("c2", "b2", (1, 0)), "k3": ("c3", "b3", (1, -1))}
    report = describe(build_topology(spring_body_model(bodies, springs, "g")))
    assert report.block_columns == ("Z[g]", "Z[t1 free end]", "Z[t2 free end]", "Z[t3 free end]")
    assert report.block_rows == ("main", "base I2", "base I3")
    assert report.blocks == (
        ("-I", "T_{t1-k0}", "T_{t2-k0}", "T_{t3-k0}"),
        ("O", "G_{t1-base}", "G_{t2-base}", "O"),
        ("O", "G_{t1-base}", "O", "G_{t3-base}"),
    )
    (body,) = report.multi_input_bodies
    assert [(i.k, i.point, i.source) for i in body.inputs] == [(1, "b1", "k1"), (2, "b2", "k2"),
                                                               (3, "b3", "k3")]
    assert (body.output, body.downstream) == ("b0", "k0")
    assert report.ubar_order == 12 + 2 * 6 == 6 * (1 + len(report.tips))


def test_book_figure_11_1_geometric_rows_of_bodies_9_10_15():
    report = describe(build_topology(book_figure_11_1()))
    assert report.root.element == "18" and len(report.tips) == 4 and not report.cuts
    assert report.ubar_order == 30
    inputs = {body.name: [i.point for i in body.inputs] for body in report.multi_input_bodies}
    assert inputs == {"9": ["b5", "b6"], "10": ["b7", "b8"], "15": ["b14", "b12"]}
    tips = [f"Z[{n} free end]" for n in "1234"]
    assert report.block_columns == ("Z[g]", *tips)
    assert report.blocks[0] == ("-I", "T_{1-18}", "T_{2-18}", "T_{3-18}", "T_{4-18}")
    expected = {"9 I2": ("O", "G_{1-9}", "G_{2-9}", "O", "O"),
                "10 I2": ("O", "O", "O", "G_{3-10}", "G_{4-10}"),
                "15 I2": ("O", "G_{1-15}", "G_{2-15}", "G_{3-15}", "G_{4-15}")}
    assert sorted(report.block_rows[1:]) == sorted(expected)
    for row, entries in expected.items():
        assert report.blocks[report.block_rows.index(row)] == entries
    paths = {path.column: path.elements for path in report.paths}
    assert paths["Z[4 free end]"] == ("4", "8", "10[I2]", "12", "15[I2]", "16", "17", "18")


def test_loop_cut_adds_a_column_and_its_supplement():
    report = describe(build_topology(loop_model()))
    (cut,) = report.cuts
    assert (cut.point, cut.elements, cut.closing) == ("q2", ("s2", "R2"), False)
    assert cut.supplement == "Z_{R2,0} = C Z_{s2,0}" and len(cut.unknowns) == 12
    assert report.block_columns == ("Z[g]", "Z[cut q2]")
    assert report.block("main", "Z[cut q2]") == "T_{s2-k0} + T_{R2-k0} C"
    assert report.block("R1 I2", "Z[cut q2]") == "G_{s2-R1} + G_{R2-R1} C"
    assert report.block("R1 I2", "Z[g]") == "O"
    assert not report.tips and report.ubar_order == 18


def test_boundaryless_ring_is_closed_at_its_root():
    report = describe(build_topology(ring_model()))
    (cut,) = report.cuts
    assert cut.closing and report.root.label == f"cut {cut.point}"
    assert report.block_columns == (f"Z[cut {cut.point}]",)
    side1, root = cut.elements[1], report.root.element
    assert report.blocks == ((f"-I + T_{{{side1}-{root}}}",),)
    assert report.ubar_order == 12 and len(report.root.unknowns) == 12


def test_junction_is_reported_and_feeds_geometric_rows():
    report = describe(build_topology(junction_model()))
    assert report.junctions == ("junction j",)
    assert report.block_rows == ("main", "junction j I2")
    assert report.blocks[1] == ("O", "G_{m1-junction j}", "G_{m2-junction j}")


def test_to_text_and_to_dict_carry_the_layout():
    report = describe(build_topology(loop_model()))
    text = report.to_text()
    assert "order of Ubar_all: 18" in text and "Z_{R2,0} = C Z_{s2,0}" in text
    header = next(line for line in text.splitlines() if "Z[cut q2]" in line and "Z[g]" in line)
    main = next(line for line in text.splitlines() if line.strip().startswith("main"))
    assert main.index("T_{s2-k0}") == header.index("Z[cut q2]")
    data = json.loads(json.dumps(report.to_dict()))
    assert data["blocks"][0] == ["-I", "T_{s2-k0} + T_{R2-k0} C"]
    assert data["cuts"][0]["elements"] == ["s2", "R2"]


@pytest.mark.parametrize("make", [chain_model, book_figure_11_1, loop_model, ring_model,
                                  junction_model])
def test_o_blocks_are_exactly_the_zero_blocks_of_the_numeric_ubar(make):
    """The symbolic layout against Deduction's own Ū_all at one frequency."""
    topology = build_topology(make())
    report = describe(topology)
    deduction = Deduction(topology)
    ubar = deduction.matrix(3.7)[0]
    rows = [slice(0, 12)] + [slice(6 + 6 * r, 12 + 6 * r) for r in range(1, len(report.block_rows))]
    for c, column in enumerate(report.block_columns):
        label = column[2:-1] + "."
        columns = [i for i, name in enumerate(deduction.columns) if name.startswith(label)]
        for r, row in enumerate(rows):
            zero = not np.any(ubar[row][:, columns])
            assert zero == (report.blocks[r][c] == "O"), (report.block_rows[r], column)


@pytest.mark.parametrize("make", [book_figure_11_1, loop_model, ring_model, junction_model])
def test_figure_is_a_png(tmp_path, make):
    path = tmp_path / "topology.png"
    plot_topology(build_topology(make()), path, title=make.__name__)
    assert path.read_bytes()[:8] == PNG_SIGNATURE and path.stat().st_size > 5000


@pytest.mark.parametrize("make", [book_figure_11_1, loop_model, ring_model, junction_model, "mlrs"])
def test_figure_labels_do_not_overlap_and_a_legend_keys_the_symbols(make):
    if make == "mlrs":
        topology = build_topology(load_model(ROOT / "models" / "mlrs" / "mlrs.toml"), root="muzzle")
    else:
        topology = build_topology(make())
    figure = topology_figure(topology, title="topology")
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    texts = [text for text in figure.axes[0].texts if text.get_text()]
    boxes = [(text.get_bbox_patch() or text).get_window_extent(renderer) for text in texts]
    for i, box in enumerate(boxes):
        overlapping = [texts[j].get_text() for j in range(i + 1, len(boxes)) if box.overlaps(boxes[j])]
        assert not overlapping, f"{texts[i].get_text()!r} overlaps {overlapping}"
    arrows = [text.arrow_patch.get_path().interpolated(40).vertices for text in figure.axes[0].texts
              if getattr(text, "arrow_patch", None) is not None]
    for text, box in zip(texts, boxes):
        if text.get_bbox_patch() is None:  # names and end labels, not the boxed or circled ones
            assert not any(box.count_contains(arrow) for arrow in arrows), f"an arrow crosses {text.get_text()!r}"
    keys = [text.get_text() for text in figure.legends[0].get_texts()]
    assert "rigid body" in keys and any("boundary end" in key for key in keys)
    assert any("loop cut" in key for key in keys) == bool(topology.cuts)
    assert any("spring" in key for key in keys) == any(e.kind == "spring" for e in topology.elements)


def test_check_command_prints_json_and_writes_the_figure(tmp_path, capsys):
    figure = tmp_path / "fig.png"
    args = cli.build_parser().parse_args(
        ["check", CHAIN, "--json", "--plot", str(figure)])
    assert args.run(args) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["model"] == "spring-mass chain" and data["ubar_order"] == 12
    assert data["blocks"] == [["-I", "T_{k3-k1}"]]
    assert figure.read_bytes()[:8] == PNG_SIGNATURE


@pytest.mark.parametrize("options", [("--root", "nowhere"), ("--plot", "missing/fig.png")])
def test_check_command_errors_are_one_line_exit_2(monkeypatch, capsys, tmp_path, options):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["check", CHAIN, *options]) == 2
    error = capsys.readouterr().err
    assert len(error.strip().splitlines()) == 1 and options[0] in error


def test_check_subcommand_end_to_end(tmp_path):
    result = subprocess.run([sys.executable, "-m", "linmstmm", "check",
                             "models/cantilever_tip_mass.toml", "--plot", str(tmp_path / "f.png")],
                            cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "T_{payload-arm}" in result.stdout and (tmp_path / "f.png").exists()
