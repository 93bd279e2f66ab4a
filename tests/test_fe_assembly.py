"""The sparse FE assembly against a dense one written out plainly.

The reference below builds the full-DOF stiffness and mass from the textbook
12 × 12 frame element matrices (not from the strain operator and its
stiffnesses that :func:`linmstmm.fe.assembly.assemble` scatters), adds the
springs as k e eᵀ and the bodies' mass blocks, writes every constraint as a
dense row (boundaries, each port riding on its body, ``inf`` spring directions,
``axial=False``), and takes its null space by SVD. Then for a model with beams,
springs, a joint, three rigid bodies (two rigidly joined at a shared port) and
a beam declared rigid axially:

* the eliminated basis T spans exactly that null space;
* K and M equal Tᵀ K_ref T and Tᵀ M_ref T to rounding;
* the parts the Wittrick–Williams count uses (:func:`constrained_parts`) give
  the springs' stiffness and the bodies' mass the same way;
* held or floating, the rigid-body and mechanism modes are as many as the zero
  eigenvalues of the dense reduced stiffness, lie in its null space and are
  M-orthonormal.
"""
from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
import scipy.linalg as la
from builders import fixed, make_beam, make_rigid, make_spring

from linmstmm.fe.assembly import assemble, constrained_parts
from linmstmm.fe.sparse import as_scipy
from linmstmm.model import Model

INF = np.inf
#: Rounding allowed, relative to the largest entry of the compared matrix.
ROUNDING = 1e-12


def mixed_model(held: bool = True) -> Model:
    """Ground spring, two bodies joined at a port, a beam, a pin, an axially rigid beam,
    a tip body; clamped at the ground point (``held``) or floating."""
    pts = {name: np.asarray(x, float) for name, x in {
        "g": [0, 0, 0], "a": [0, 0, 0], "b": [0.6, 0.0, 0.0], "f": [0.6, -0.4, 0.1],
        "c": [1.6, 0.2, 0.1], "d": [1.6, 0.2, 0.1], "e": [2.4, 0.3, 0.5]}.items()}
    turn = la.expm(np.cross(np.eye(3), [0.2, -0.3, 0.5]))            # spring axes off the inertial ones
    springs = (make_spring("mount", "g", "a", [1e5, 2e5, 3e5, INF, 4e4, INF], axes=turn),
               make_spring("pin", "c", "d", [INF, INF, INF, INF, INF, 0.0], release=("rz",)))
    inertia = np.array([[0.5, 0.02, -0.01], [0.02, 0.7, 0.03], [-0.01, 0.03, 0.9]])
    rigids = (make_rigid("hub", ["a", "b"], 5.0, [0.3, 0.1, 0.05], inertia),
              make_rigid("arm", ["b", "f"], 2.0, [0.6, -0.2, 0.05], [0.1, 0.2, 0.3]),
              make_rigid("tip", ["e"], 1.5, [2.4, 0.35, 0.5], [0.01, 0.02, 0.03]))
    beams = (make_beam("boom", "b", "c", pts, Iy=3e-7),
             make_beam("link", "d", "e", pts, A=5e-4, Iz=1e-7, axial=False))
    return Model("mixed", pts, rigids=rigids, beams=beams, springs=springs,
                 boundary={"g": fixed()} if held else {})


def frame_stiffness(beam, h: float) -> np.ndarray:
    """(12, 12) textbook Euler–Bernoulli frame element stiffness, local DOFs."""
    k = np.zeros((12, 12))
    rod = np.array([[1.0, -1.0], [-1.0, 1.0]])
    k[np.ix_([0, 6], [0, 6])] = beam.E * beam.A / h * rod
    k[np.ix_([3, 9], [3, 9])] = beam.G * beam.J / h * rod
    for dofs, inertia, sign in (([1, 5, 7, 11], beam.Iz, 1.0), ([2, 4, 8, 10], beam.Iy, -1.0)):
        s = sign * h
        k[np.ix_(dofs, dofs)] = beam.E * inertia / h ** 3 * np.array([
            [12.0, 6 * s, -12.0, 6 * s], [6 * s, 4 * h * h, -6 * s, 2 * h * h],
            [-12.0, -6 * s, 12.0, -6 * s], [6 * s, 2 * h * h, -6 * s, 4 * h * h]])
    return k


def frame_mass(beam, h: float) -> np.ndarray:
    """(12, 12) textbook consistent mass without rotary inertia, local DOFs."""
    m = np.zeros((12, 12))
    rod = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6
    m[np.ix_([0, 6], [0, 6])] = beam.rho * beam.A * h * rod
    m[np.ix_([3, 9], [3, 9])] = beam.rho * beam.Ip * h * rod
    for dofs, sign in (([1, 5, 7, 11], 1.0), ([2, 4, 8, 10], -1.0)):
        s = sign * h
        m[np.ix_(dofs, dofs)] = beam.rho * beam.A * h / 420 * np.array([
            [156.0, 22 * s, 54.0, -13 * s], [22 * s, 4 * h * h, 13 * s, -3 * h * h],
            [54.0, 13 * s, 156.0, -22 * s], [-13 * s, -3 * h * h, -22 * s, 4 * h * h]])
    return m


def dense_reference(model: Model, fe) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Full-DOF (K_springs, K_beams, M_bodies, M_beams, constraint rows), on the node
    numbering of ``fe`` (point and mass-centre DOFs inertial, interior beam nodes in
    the beam's axes)."""
    index, n = fe.dof_index, fe.n_full
    k_springs, k_beams, m_bodies, m_beams = (np.zeros((n, n)) for _ in range(4))
    rows = []

    def row(entries):
        r = np.zeros(n)
        for dof, value in entries:
            r[dof] += value
        rows.append(r)

    ends = set(index.points.values())
    for beam in model.beams:
        nodes = index.beam_nodes[beam.name]
        h = beam.length / (len(nodes) - 1)
        for first, second in pairwise(nodes):
            # local = rotation @ full: a point's DOFs are inertial, an interior node's the beam's
            rotation = la.block_diag(*[beam.axes if node in ends else np.eye(3)
                                       for node in (first, first, second, second)])
            dofs = np.r_[6 * first + np.arange(6), 6 * second + np.arange(6)]
            k_beams[np.ix_(dofs, dofs)] += rotation.T @ frame_stiffness(beam, h) @ rotation
            m_beams[np.ix_(dofs, dofs)] += rotation.T @ frame_mass(beam, h) @ rotation
            if not beam.axial:                                        # u2 − u1 along the axis
                rows.append(np.zeros(n))
                rows[-1][dofs] = rotation[6] - rotation[0]
    for spring in model.springs:
        a, b = (index.point(end) for end in spring.ends)
        for c in range(6):
            block = slice(0, 3) if c < 3 else slice(3, 6)
            e = np.zeros(n)
            e[a[block]], e[b[block]] = -spring.axes[c % 3], spring.axes[c % 3]
            if spring.release is not None and spring.release[c]:
                continue
            if np.isinf(spring.k[c]):
                rows.append(e)
            else:
                k_springs += spring.k[c] * np.outer(e, e)
    for body in model.rigids:
        centre = index.rigid(body.name)
        m_bodies[centre[:3], centre[:3]] += body.mass
        m_bodies[np.ix_(centre[3:], centre[3:])] += body.inertia
        for port in body.ports:
            # u_p − u_c + arm × θ_c = 0 and θ_p − θ_c = 0, arm = p − c
            p, arm = index.point(port), model.points[port] - body.com
            turn = np.cross(arm, np.eye(3))                           # row j: arm × e_j
            for i in range(3):
                row([(p[i], 1.0), (centre[i], -1.0)] + [(centre[3 + j], turn[j, i]) for j in range(3)])
                row([(p[3 + i], 1.0), (centre[3 + i], -1.0)])
    for point, components in model.boundary.items():
        for dof in index.point(point)[np.asarray(components, bool)]:
            row([(dof, 1.0)])
    return k_springs, k_beams, m_bodies, m_beams, np.array(rows)


def relative(a, b) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


@pytest.mark.parametrize("elements_per_beam", [1, 2, 3])
def test_assembly_equals_the_dense_reference(elements_per_beam):
    model = mixed_model()
    fe = assemble(model, elements_per_beam)
    k_springs, k_beams, m_bodies, m_beams, constraints = dense_reference(model, fe)
    T = fe.T.toarray()
    null = la.null_space(constraints)
    assert np.abs(constraints @ T).max() < ROUNDING * np.abs(constraints).max() * np.abs(T).max()
    assert np.linalg.matrix_rank(T) == T.shape[1] == null.shape[1]
    assert relative(fe.K.toarray(), T.T @ (k_springs + k_beams) @ T) < ROUNDING
    assert relative(fe.M.toarray(), T.T @ (m_bodies + m_beams) @ T) < ROUNDING
    G = fe.G.toarray()
    assert relative(G.T @ np.diag(fe.D) @ G, fe.K.toarray()) < ROUNDING
    assert fe.K.toarray().tolist() == fe.K.T.toarray().tolist()       # symmetric bit for bit


def test_constrained_parts_equal_the_dense_reference():
    model = mixed_model()
    parts = constrained_parts(model, 1)
    k_springs, _, m_bodies, _, constraints = dense_reference(model, assemble(model, 1))
    T = as_scipy(parts.T).toarray()
    assert np.abs(constraints @ T).max() < ROUNDING * np.abs(constraints).max() * np.abs(T).max()
    assert T.shape[1] == la.null_space(constraints).shape[1]
    assert np.array_equal(T[parts.masters], np.eye(T.shape[1]))        # the masters are full DOFs
    strains = parts.spring_strains.matrix(parts.n_full).toarray()
    stiffness = np.concatenate(parts.spring_stiffness)
    assert relative(T.T @ strains.T @ np.diag(stiffness) @ strains @ T, T.T @ k_springs @ T) < ROUNDING
    rigid_mass = parts.rigid_mass.matrix(parts.n_full, parts.n_full).toarray()
    assert relative(T.T @ rigid_mass @ T, T.T @ m_bodies @ T) < ROUNDING


@pytest.mark.parametrize("held, expected", [(True, 1), (False, 7)])
def test_rigid_body_modes_are_the_reference_stiffness_null_space(held, expected):
    """The pin lets the link and tip body turn: one mechanism held, and six rigid-body
    modes more floating."""
    model = mixed_model(held)
    fe = assemble(model, 2)
    k_springs, k_beams, _, _, _ = dense_reference(model, fe)
    T = fe.T.toarray()
    reduced = T.T @ (k_springs + k_beams) @ T
    scale = 1 / np.sqrt(np.abs(np.diag(reduced)) + np.diag(fe.M.toarray()))
    eigenvalues = la.eigvalsh(reduced * np.outer(scale, scale))
    zero = np.count_nonzero(np.abs(eigenvalues) < 1e-9 * eigenvalues.max())
    modes = fe.rigid_modes
    assert modes.shape[1] == zero == expected
    assert np.abs(reduced @ modes).max() < 1e-9 * np.abs(reduced).max() * np.abs(modes).max()
    assert np.allclose(modes.T @ fe.M.toarray() @ modes, np.eye(expected), atol=1e-12)
