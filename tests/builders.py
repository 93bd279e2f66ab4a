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
