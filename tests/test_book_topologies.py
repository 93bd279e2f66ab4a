"""Topologies drawn in chapter 11 of Rui, Wang and Zhang, "Transfer Matrix Method for
Multibody Systems: Theory and Applications" (Wiley, 2018; docs/method.md).

Figure 11.1: a tree whose bodies 9, 10 and 15 each have two inputs (hinges 5
and 6, 7 and 8, 14 and 12), tips 1-4, and an output chain 15 → 16 → 17 → 18
to the root boundary. Parameters are plausible (kg, m, N/m, N m/rad); the
check is the finite-element route.

Figure 11.7: the closed loop of three masses m and three springs k. Along
the ring only the stretch of each spring is elastic; exactly ω² = 0 (the
ring moving as a whole) and ω² = 3k/m twice.
"""
from __future__ import annotations

import numpy as np
import pytest

from builders import fixed, make_rigid, make_spring
from linmstmm.fe import fe_frequencies
from linmstmm.model import Model, load_model
from linmstmm.solve import natural_frequencies
from linmstmm.topology import build_topology
from random_models import (loop_connections, mstmm_frequencies, random_rotation, relative, reordered,
                           to_toml)

INF = np.inf


# --------------------------------------------------------------------------
# Figure 11.1

#: Bodies: name -> (mass kg, mass centre m, [(port, position m)], output port first).
FIG_11_1_BODIES = {
    "B1": (2.0, (0.10, 0.05, 2.30), [("b1", (0.20, 0.00, 2.00))]),
    "B2": (2.5, (0.70, -0.05, 2.30), [("b2", (0.60, 0.00, 2.00))]),
    "B3": (1.5, (-0.80, 0.10, 2.70), [("b3", (-0.70, 0.00, 2.40))]),
    "B4": (3.0, (-0.20, -0.10, 2.70), [("b4", (-0.30, 0.00, 2.40))]),
    "B9": (6.0, (0.40, 0.02, 1.60), [("b9o", (0.30, 0.00, 1.20)), ("b9a", (0.20, 0.00, 2.00)),
                                      ("b9b", (0.60, 0.00, 2.00))]),
    "B10": (5.0, (-0.50, -0.02, 2.10), [("b10o", (-0.50, 0.00, 1.80)), ("b10a", (-0.70, 0.00, 2.40)),
                                         ("b10b", (-0.30, 0.00, 2.40))]),
    "B13": (4.0, (-0.40, 0.03, 1.50), [("b13o", (-0.30, 0.00, 1.20)), ("b13i", (-0.50, 0.00, 1.80))]),
    "B15": (10.0, (0.00, 0.00, 0.90), [("b15o", (0.00, 0.00, 0.60)), ("b15a", (-0.30, 0.00, 1.20)),
                                        ("b15b", (0.30, 0.00, 1.20))]),
    "B17": (12.0, (0.00, 0.05, 0.30), [("b17o", (0.00, 0.00, 0.00)), ("b17i", (0.00, 0.00, 0.60))]),
}
#: Hinges: name -> (upstream point, downstream point, [k_x, k_y, k_z, k_rx, k_ry, k_rz]).
FIG_11_1_HINGES = {
    "H5": ("b1", "b9a", [4e4, 5e4, 6e4, 900.0, 1100.0, 800.0]),
    "H6": ("b2", "b9b", [5e4, 4e4, 7e4, 1200.0, 700.0, 1000.0]),
    "H7": ("b3", "b10a", [3e4, 6e4, 5e4, 600.0, 900.0, 1300.0]),
    "H8": ("b4", "b10b", [6e4, 3e4, 4e4, 1000.0, 1200.0, 500.0]),
    "H11": ("b10o", "b13i", [1e5, 2e5, 1.5e5, 3000.0, 2500.0, 2000.0]),
    "H12": ("b9o", "b15b", [2e5, 1e5, 2.5e5, 2000.0, 3500.0, 2500.0]),
    "H14": ("b13o", "b15a", [1.5e5, 2.5e5, 2e5, 2500.0, 3000.0, 4000.0]),
    "H16": ("b15o", "b17i", [5e5, 4e5, 6e5, 8000.0, 9000.0, 7000.0]),
    "H18": ("b17o", "ground", [8e5, 9e5, 1e6, 1.5e4, 1.2e4, 1e4]),
}


def box_inertia(mass, size, rotation) -> np.ndarray:
    """Inertia tensor (inertial axes) of a solid box of ``size`` m turned by ``rotation``."""
    a, b, c = size
    principal = mass / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    return rotation.T @ np.diag(principal) @ rotation


def figure_11_1() -> Model:
    """The tree of Figure 11.1 (each hinge joins two coinciding points)."""
    rng = np.random.default_rng(111)
    points, bodies = {"ground": np.zeros(3)}, []
    for name, (mass, com, ports) in FIG_11_1_BODIES.items():
        for port, position in ports:
            points[port] = np.array(position)
        inertia = box_inertia(mass, rng.uniform(0.15, 0.4, 3), random_rotation(rng))
        bodies.append(make_rigid(name, [p for p, _ in ports], mass, com, (inertia + inertia.T) / 2))
    springs = [make_spring(name, a, b, k, random_rotation(rng))
               for name, (a, b, k) in FIG_11_1_HINGES.items()]
    return Model("Figure 11.1 tree", points, rigids=tuple(bodies), springs=tuple(springs),
                 boundary={"ground": fixed()})


@pytest.fixture(scope="module")
def tree():
    return figure_11_1()


@pytest.fixture(scope="module")
def tree_frequencies(tree):
    return natural_frequencies(tree, count=10)


def test_figure_11_1_topology(tree, tmp_path):
    """A valid model file; root at the ground, tips 1-4, and exactly bodies 9,
    10, 15 with two inputs each."""
    (tmp_path / "tree.toml").write_text(to_toml(tree))
    assert len(load_model(tmp_path / "tree.toml").elements) == 18
    topology = build_topology(tree)
    assert topology.root_label == "ground"
    assert sorted(b.label for b in topology.boundaries) == sorted(
        ["ground"] + [f"B{i} free end" for i in range(1, 5)])
    two_inputs = {el.name: sorted(el.ports[p].point for p in el.inputs)
                  for el in topology.elements if len(el.inputs) > 1}
    assert two_inputs == {"B9": ["b9a", "b9b"], "B10": ["b10a", "b10b"], "B15": ["b15a", "b15b"]}
    assert not topology.cuts


def test_figure_11_1_agrees_with_fe(tree, tree_frequencies):
    reference = fe_frequencies(tree, count=10)
    assert tree_frequencies.rigid_body_modes == reference.rigid_body_modes == 0
    assert relative(tree_frequencies.frequencies_hz, reference.frequencies_hz) <= 1e-7
    assert 0.5 < tree_frequencies.frequencies_hz[0] and tree_frequencies.frequencies_hz[-1] < 1000


@pytest.mark.parametrize("root", ["B1 free end", "B4 free end"])
def test_figure_11_1_does_not_depend_on_the_root(tree, tree_frequencies, root):
    assert relative(mstmm_frequencies(tree, root=root), tree_frequencies.frequencies_hz) <= 1e-9


# --------------------------------------------------------------------------
# Figure 11.7

def ring_of_three(k, m, direction=(1.0, 0.0, 0.0), guided=False) -> Model:
    """Masses m6, m2, m4 round a ring joined by springs K1, K3, K5 of stiffness k.

    The ring is drawn along ``direction``: each body spans one unit step, the
    third one back to the start, so the springs sit at 0, 1, 2 steps. Springs
    are rigid in every direction but the stretch. ``guided``: every body is
    also held in y, z and all rotations (direction must be x); otherwise the
    ring floats and keeps six rigid-body modes.
    """
    e = np.asarray(direction, float) / np.linalg.norm(direction)
    helper = np.array([0.0, 0.0, 1.0]) if abs(e[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    y = np.cross(helper, e) / np.linalg.norm(np.cross(helper, e))
    axes = np.array([e, y, np.cross(e, y)])
    points, bodies, springs = {}, [], []
    for i, (body, spring) in enumerate((("m6", "K1"), ("m2", "K3"), ("m4", "K5"))):
        points[f"in{i}"] = i * e
        points[f"out{i}"] = ((i + 1) % 3) * e
        com = (points[f"in{i}"] + points[f"out{i}"]) / 2
        bodies.append(make_rigid(body, [f"in{i}", f"out{i}"], m, com, (m, m, m)))
        springs.append(make_spring(spring, f"out{i}", f"in{(i + 1) % 3}", [k] + [INF] * 5, axes))
    boundary = {f"in{i}": fixed("y", "z", "rx", "ry", "rz") for i in range(3)} if guided else {}
    return Model("Figure 11.7 ring", points, rigids=tuple(bodies), springs=tuple(springs),
                 boundary=boundary)


K, M = 2.0e4, 3.0
EXACT_HZ = np.full(2, np.sqrt(3 * K / M) / (2 * np.pi))
#: The floating ring drawn along a direction that is not an inertial axis.
SKEW = (0.48, -0.6, 0.64)
@pytest.mark.parametrize("direction, guided, rigid", [
    pytest.param((1, 0, 0), True, 1, id="x-guided"),
    pytest.param((1, 0, 0), False, 6, id="x-floating"),
    pytest.param((0, 0, 1), False, 6, id="z-floating"),
    pytest.param(SKEW, False, 6, id="skew-floating")])
def test_figure_11_7_exact(direction, guided, rigid):
    got = natural_frequencies(ring_of_three(K, M, direction, guided), count=4)
    assert got.rigid_body_modes == rigid
    assert len(got.frequencies_hz) == 2
    assert relative(got.frequencies_hz, EXACT_HZ) <= 1e-12


@pytest.mark.parametrize("root", ["in0", "in1", "in2"])
@pytest.mark.parametrize("cut", ["out0", "out1", "out2"])
def test_figure_11_7_guided_does_not_depend_on_root_or_cut(root, cut):
    ring = ring_of_three(K, M, guided=True)
    assert cut in loop_connections(ring)
    assert relative(mstmm_frequencies(ring, count=4, root=root, cut_at=(cut,)), EXACT_HZ) <= 1e-12


@pytest.mark.parametrize("direction", [pytest.param((1, 0, 0), id="x"),
                                       pytest.param(SKEW, id="skew")])
def test_figure_11_7_floating_does_not_depend_on_the_closing_point(direction):
    """No boundary end: the loop is closed at the first connection in record
    order; rotating the records moves it round the ring."""
    closing = []
    for shift in range(3):
        ring = reordered(ring_of_three(K, M, direction), shift)
        closing.append(build_topology(ring).cuts[0].point)
        assert relative(mstmm_frequencies(ring, count=4), EXACT_HZ) <= 1e-12, closing[-1]
    assert len(set(closing)) == 3
