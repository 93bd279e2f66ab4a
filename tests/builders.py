"""Small builders of model records for tests (no TOML needed)."""
from __future__ import annotations

import numpy as np

from linmstmm.model import Beam, Model, Rigid, Spring

STEEL = dict(E=2.1e11, G=8.1e10, rho=7850.0)


def beam_axes(a, b, y_hint=None) -> np.ndarray:
    """(3, 3) rows local x, y, z for a beam from a to b (contract default for y)."""
    x = (np.asarray(b, float) - np.asarray(a, float))
    x /= np.linalg.norm(x)
    y = np.cross([0.0, 0.0, 1.0], x) if y_hint is None else np.asarray(y_hint, float)
    if np.linalg.norm(y - (y @ x) * x) < 1e-9:
        y = np.array([0.0, 1.0, 0.0])
    y = y - (y @ x) * x
    y /= np.linalg.norm(y)
    return np.array([x, y, np.cross(x, y)])


def make_beam(name, a, b, points, A=1e-3, Iy=2e-7, Iz=2e-7, J=4e-7, Ip=None, y_hint=None,
              material=STEEL, **options) -> Beam:
    """Beam between named points with section properties (SI)."""
    pa, pb = np.asarray(points[a], float), np.asarray(points[b], float)
    return Beam(name, (a, b), material["E"], material["G"], material["rho"], A, Iy, Iz, J,
                Iy + Iz if Ip is None else Ip, beam_axes(pa, pb, y_hint),
                float(np.linalg.norm(pb - pa)), **options)


def make_rigid(name, ports, mass, com, inertia=(0.0, 0.0, 0.0)) -> Rigid:
    inertia = np.asarray(inertia, float)
    return Rigid(name, tuple(ports), mass, np.asarray(com, float),
                 np.diag(inertia) if inertia.ndim == 1 else inertia)


def make_spring(name, a, b, k, axes=None) -> Spring:
    return Spring(name, (a, b), np.asarray(k, float), np.eye(3) if axes is None else np.asarray(axes))


def fixed(*components) -> np.ndarray:
    """(6,) fixed mask; no arguments = fully fixed."""
    names = ("x", "y", "z", "rx", "ry", "rz")
    return np.array([not components or n in components for n in names])


def single_beam_model(left=None, right=None, length=2.0, **beam_options) -> Model:
    """One beam along x from 'a' to 'b' with boundary masks (None = free)."""
    points = {"a": np.zeros(3), "b": np.array([length, 0.0, 0.0])}
    boundary = {p: mask for p, mask in (("a", left), ("b", right)) if mask is not None}
    return Model("beam", points, beams=(make_beam("beam", "a", "b", points, **beam_options),),
                 boundary=boundary)


def spring_mass_chain(k=1000.0, m=2.0, damping=None) -> Model:
    """fixed–k–3m–k–m–k–fixed along x; rotations locked by rigid rotational springs.

    Every translation direction repeats the 1-D chain: ω² = (4 ∓ √7)/3 · k/m, three times each.
    damping : the model's (alpha, beta), or None.
    """
    points = {name: np.array([x, 0.0, 0.0]) for name, x in
              [("g0", 0.0), ("a1", 0.0), ("b1", 1.0), ("a2", 1.0), ("b2", 2.0), ("g3", 2.0)]}
    stiff = [k, k, k, np.inf, np.inf, np.inf]
    return Model(
        "spring-mass chain", points,
        rigids=(make_rigid("m1", ["a1", "b1"], 3 * m, [0.5, 0, 0]),
                make_rigid("m2", ["a2", "b2"], m, [1.5, 0, 0])),
        springs=(make_spring("k1", "g0", "a1", stiff), make_spring("k2", "b1", "a2", stiff),
                 make_spring("k3", "b2", "g3", stiff)),
        boundary={"g0": fixed(), "g3": fixed()}, damping=damping)
