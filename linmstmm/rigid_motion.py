"""Rigid-body (zero-frequency) modes from the model's kinematics.

A zero-frequency mode stores no strain energy. Every spring is stiff in all
six directions (k > 0, or ``inf``) except those a joint releases, and every
beam has E, G > 0, so zero strain means that each *segment* of the model
(points joined by rigid bodies, beams and springs without a released
direction) moves as one rigid body, and that across every joint the two
segments it joins move alike in each direction it keeps. The zero-energy
motions of a connected part are therefore the six unit motions of each of
its segments (translations, and rotations about the part's centroid scaled by
its extent so that both weigh alike), less those its fixed boundary
components and its joints' kept directions hold: rigid-body modes and
mechanism modes (a four-bar linkage's one) alike. That is the null space of
a small matrix of pure geometry: direction cosines and lengths relative to
the part's own extent, so its rank is decided at a relative tolerance that no
choice of units or overall size changes (Ū_all(0), by contrast, mixes the
stiffness and length scales of the model, and its small singular values say
little about its null space).

A motion counts as a mode only if it moves mass: a free point mass without
rotary inertia has three rigid-body modes, not six.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as la

from linmstmm.model import Model
from linmstmm.model_structure import MODELS_KEPT, KeptByStructure
from linmstmm.union_find import components

#: A boundary row of the geometry matrix is independent of the others above
#: this fraction of the largest singular value (entries are direction cosines
#: and ratios of lengths to the part's extent, all of order one).
GEOMETRIC_RANK = 1e-10
#: A rigid motion whose kinetic energy is below this fraction of the part's
#: largest moves no mass (a rotation about a lone point mass).
MASSLESS_MOTION = 1e-13


def connected_parts(model: Model) -> tuple[list[list[str]], list[list[str]]]:
    """(parts, segments): the point names of each connected part of ``model``, and of
    each segment, both in order of first appearance.

    Two points are in one part when elements join them (a rigid body's ports,
    a beam's or a spring's ends), in one segment when elements other than
    springs with a released direction join them (a segment moves as one rigid
    body in a zero-energy motion): see :func:`_point_labels`.
    """
    names = np.array(list(model.points), dtype=object)
    return tuple([list(names[members]) for members in _members(labels)] for labels in _point_labels(model))


def _point_labels(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """(part, segment): (points,) int each, the connected part and the segment of every
    point of ``model`` (in ``model.points`` order), each numbered in order of first
    appearance: the components (:func:`~linmstmm.union_find.components`) of the graph
    of points joined by every element (each element's other ends to its first), and of
    that graph less its joints. On the launcher 15 µs against 0.14 ms for scipy's sparse-graph components
    (a checked sparse matrix per graph); a 10,000-body chain 12 ms against 10.
    """
    number = {name: i for i, name in enumerate(model.points)}
    edges, joint = [], []
    for element in model.elements:
        ends = element.ports if element.kind == "rigid" else element.ends
        released = element.kind == "spring" and element.released.size > 0
        for other in ends[1:]:
            edges.append((number[ends[0]], number[other]))
            joint.append(released)
    segments = components(len(number), [edge for edge, cut in zip(edges, joint) if not cut])
    return (components(len(number), edges) if any(joint) else segments), segments


def _members(labels: np.ndarray) -> list[np.ndarray]:
    """The indices carrying each label 0, 1, ... of ``labels`` ((n,) int), ascending."""
    by_label = np.argsort(labels, kind="stable")
    return np.split(by_label, np.cumsum(np.bincount(labels))[:-1]) if labels.size else []


def unit_motions(positions: np.ndarray, centre: np.ndarray, size: float) -> np.ndarray:
    """(n, 6, 6) displacement and rotation of n points under the six unit motions.

    positions : (n, 3) m. centre : (3,) m, the rotation centre. size : m, the
    length that scales the rotations (a unit rotation turns by 1/size rad).
    Entry [p, :, k] is point p's (u, θ) under motion k: translations along x,
    y, z, then rotations about x, y, z through ``centre``.
    """
    arm = np.asarray(positions, float) - centre
    field = np.zeros((len(arm), 6, 6))
    field[:, :3, :3] = np.eye(3)
    field[:, :3, 3:] = -skew_stack(arm) / size  # θ × r = −r × θ
    field[:, 3:, 3:] = np.eye(3) / size
    return field


def skew_stack(vectors: np.ndarray) -> np.ndarray:
    """(n, 3, 3) cross-product matrices of (n, 3) float vectors: skew(r) @ a = r × a
    (:func:`~linmstmm.elements.frames.skew` of each, written at once)."""
    x, y, z = np.asarray(vectors, dtype=float).reshape(-1, 3).T
    zero = np.zeros_like(x)
    return np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=1).reshape(-1, 3, 3)


def _kinetic_matrix(model: Model, part: set, centre: np.ndarray, size: float) -> np.ndarray:
    """(6, 6) kinetic-energy matrix (×2/ω²) of the part's six unit motions, kg.

    Rigid bodies by their mass and inertia; beams as rigid rods (mass ρAL at
    mid-length, ρAL³/12 about axes across, ρ Ip L about their own axis).
    """
    kinetic = np.zeros((6, 6))
    for body in model.rigids:
        if body.ports[0] in part:
            kinetic += _body_kinetic(body.mass, body.com, body.inertia, centre, size)
    for beam in model.beams:
        if beam.ends[0] in part:
            axis = beam.axes[0]
            rod = beam.rho * beam.A * beam.length
            inertia = rod * beam.length ** 2 / 12 * (np.eye(3) - np.outer(axis, axis))
            inertia += beam.rho * beam.Ip * beam.length * np.outer(axis, axis)
            middle = 0.5 * (model.points[beam.ends[0]] + model.points[beam.ends[1]])
            kinetic += _body_kinetic(rod, middle, inertia, centre, size)
    return kinetic


def _body_kinetic(mass, com, inertia, centre, size) -> np.ndarray:
    """(6, 6) kinetic-energy matrix of one body under the unit motions (kg)."""
    at_com = unit_motions(np.asarray(com, float)[None], centre, size)[0]
    body = np.zeros((6, 6))
    body[:3, :3] = mass * np.eye(3)
    body[3:, 3:] = inertia
    return at_com.T @ body @ at_com


def rigid_body_motions(model: Model) -> dict[str, np.ndarray]:
    """Point motions of every zero-frequency (rigid-body or mechanism) mode of ``model``.

    Returns point name -> (6, r): the (u, θ) of that point (m, rad, up to a
    common scale per mode) in each of the r zero-frequency modes. The modes of
    each connected part are orthonormal in its segments' unit motions and move
    mass (see :data:`MASSLESS_MOTION`).
    """
    stacked = _motions(model)
    return {name: stacked[i] for i, name in enumerate(model.points)}


def _motions(model: Model) -> np.ndarray:
    """(points, 6, r): :func:`rigid_body_motions` of every point, in ``model.points`` order."""
    columns = []
    names = list(model.points)
    segments, free = _free_parts.get(model, _parts_that_may_move)
    for members in free:
        part = [names[i] for i in members]
        segment_of = dict(zip(part, segments[members].tolist()))
        motion = _part_motions(model, part, segment_of)
        if motion is not None:
            columns.append(np.zeros((len(names), 6, motion.shape[2])))
            columns[-1][members] = motion
    return np.concatenate(columns, axis=2) if columns else np.zeros((len(names), 6, 0))


def _parts_that_may_move(model: Model) -> tuple[np.ndarray, list[np.ndarray]]:
    """((points,) segment of every point (:func:`_point_labels`), the points of each
    connected part that is not one segment held in all six directions, which has no
    motion (most grounded models)): the model's structure alone decides them."""
    parts, segments = _point_labels(model)
    segments.setflags(write=False)  # kept for every model of the structure
    fixed = {name for name, mask in model.boundary.items() if np.asarray(mask).all()}  # held in all six directions
    held = parts[[i for i, name in enumerate(model.points) if name in fixed]]
    part_of_segment = np.zeros(segments.max(initial=-1) + 1, dtype=int)
    part_of_segment[segments] = parts
    still = np.zeros(parts.max(initial=-1) + 1, dtype=bool)
    still[held[np.bincount(part_of_segment, minlength=still.size)[held] == 1]] = True
    return segments, [members for members in _members(parts) if not still[parts[members[0]]]] if not still.all() else []


#: :func:`_parts_that_may_move` of the last structures seen (a parameter study's models share one).
_free_parts = KeptByStructure(MODELS_KEPT)


def _part_motions(model: Model, part: list, segment_of: dict) -> np.ndarray | None:
    """(len(part), 6, r) motions of the points of one connected part (names ``part``,
    ``segment_of``: name -> segment) in its r zero-frequency modes, or None if none."""
    members = set(part)
    positions = np.array([model.points[p] for p in part])
    coms = [body.com for body in model.rigids if body.ports[0] in members]
    extent = np.vstack([positions] + [np.asarray(c, float)[None] for c in coms])
    centre = extent.mean(axis=0)
    size = float(np.abs(extent - centre).max()) or 1.0
    segments = list(dict.fromkeys(segment_of[p] for p in part))  # this part's, in order
    field = _segment_field(unit_motions(positions, centre, size), [segments.index(segment_of[p]) for p in part],
                           len(segments))
    index = {p: i for i, p in enumerate(part)}
    held = _held_motions(model, part, index, field, size, segment_of)
    allowed = la.null_space(held, rcond=GEOMETRIC_RANK) if held.size else np.eye(field.shape[2])
    if not allowed.shape[1]:
        return None
    kinetic = la.block_diag(*[_kinetic_matrix(model, {p for p in part if segment_of[p] == segment},
                                              centre, size) for segment in segments])
    energy, directions = la.eigh(allowed.T @ kinetic @ allowed)
    moving = allowed @ directions[:, energy > MASSLESS_MOTION * max(np.abs(kinetic).max(), 0.0)]
    return field @ moving if moving.shape[1] else None


def _segment_field(field: np.ndarray, segment: list, count: int) -> np.ndarray:
    """(n, 6, 6 count): the unit motions ``field`` (n, 6, 6) of n points, each
    point's placed in the columns of its segment (``segment[i]`` of ``count``)."""
    placed = np.zeros(field.shape[:2] + (6 * count,))
    columns = 6 * np.asarray(segment, dtype=int).reshape(-1, 1, 1) + np.arange(6)    # (n, 1, 6)
    placed[np.arange(len(field))[:, None, None], np.arange(6)[:, None], columns] = field
    return placed


def _held_motions(model: Model, part: list, index: dict, field: np.ndarray, size: float,
                  segment_of: dict) -> np.ndarray:
    """(h, 6 segments) rows that vanish under an allowed motion of the part: its fixed
    boundary components, and the relative motion across each of its joints in the
    directions the joint keeps (in the joint's axes). Rotation rows are scaled by
    ``size`` so that every row is of order one. A joint whose ends are in one segment
    (``segment_of``: point -> segment) holds nothing: its ends move alike (to the
    tolerance within which they coincide, which is no row of the matrix)."""
    weight = np.r_[np.ones(3), np.full(3, size)]
    rows = [(weight[:, None] * field[index[p]])[model.boundary[p]] for p in part if p in model.boundary]
    for spring in model.springs:
        a, b = spring.ends
        if spring.released.size and a in index and segment_of[a] != segment_of[b]:
            relative = weight[:, None] * (field[index[b]] - field[index[a]])
            local = np.kron(np.eye(2), np.asarray(spring.axes, float)) @ relative
            rows.append(np.delete(local, spring.released, axis=0))
    return np.concatenate(rows) if rows else np.zeros((0, field.shape[2]))


def held_still(deduction) -> bool:
    """True where the deduced model surely has no zero-frequency mode, read off its deduction.

    Without a joint (no jump unknowns: no spring with a released direction) each
    connected part is one segment; the model's elements are connected (its topology
    was built, :func:`linmstmm.topology.build_topology`), so where one boundary end is
    held in all six directions they are one segment held, with no motion, and points
    that no element uses move no mass: :func:`rigid_body_mode_count` is 0, found
    without the graph of points (both launchers: 80 µs on a first solve).

    Parameters
    ----------
    deduction : linmstmm.deduction.Deduction
        The model's deduction.

    Returns
    -------
    bool
        False says nothing: count the modes.
    """
    return not deduction.jump_columns and any(boundary.fixed.all() for boundary in deduction.topology.boundaries)


def rigid_body_mode_count(model: Model) -> int:
    """Number of zero-frequency (rigid-body) modes of ``model``: see the module text."""
    return _motions(model).shape[2]
