"""The model contract: immutable element records and the TOML loader.

A model file (``shared/spec/model-format.md``) is read with :mod:`tomllib`,
validated completely, and only then turned into the records below. Nothing
downstream re-validates: a :class:`Model` is always well formed.

Units are SI throughout (m, kg, s, N, rad).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Names of the six displacement components, in state-vector order.
COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")


class ModelError(ValueError):
    """A model file that breaks the contract.

    ``str(error)`` is the one line shown to the user: file, element, key and
    what is wrong, e.g. ``model.toml: spring 'k1': key 'k': k[2] must be > 0``.
    """

    def __init__(self, file, message, element=None, key=None):
        self.file = str(file)
        self.element = element
        self.key = key
        self.message = message
        parts = [self.file]
        if element is not None:
            parts.append(element)
        if key is not None:
            parts.append(f"key '{key}'")
        super().__init__(": ".join(parts + [message]))


@dataclass(frozen=True, eq=False)
class Rigid:
    """Rigid body.

    ports : point names on the body (one or more), in file order.
    mass : kg. com : (3,) mass centre, m, inertial frame.
    inertia : (3, 3) symmetric tensor about the mass centre, kg m^2, inertial axes.
    """

    name: str
    ports: tuple[str, ...]
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    kind: str = field(default="rigid", init=False)


@dataclass(frozen=True, eq=False)
class Spring:
    """Elastic hinge: massless, zero length, between coinciding points.

    k : (6,) stiffnesses [kx, ky, kz, krx, kry, krz] in the spring's local axes,
        N/m and N m/rad; ``inf`` = rigid in that direction.
    axes : (3, 3) rows = local x, y, z unit vectors in the inertial frame.
    c : (6,) viscous damping in the same layout, N s/m and N m s/rad, or None.
    """

    name: str
    ends: tuple[str, str]
    k: np.ndarray
    axes: np.ndarray
    c: np.ndarray | None = None
    kind: str = field(default="spring", init=False)


@dataclass(frozen=True, eq=False)
class Beam:
    """Straight uniform Euler-Bernoulli beam from ``ends[0]`` (local x = 0) to ``ends[1]``.

    E, G : Pa. rho : kg/m^3 (0 = massless). A : m^2. Iy, Iz, J, Ip : m^4.
    axes : (3, 3) rows = local x, y, z unit vectors in the inertial frame.
    length : m. axial / torsion : False = rigid in that deformation, inertia kept.
    """

    name: str
    ends: tuple[str, str]
    E: float
    G: float
    rho: float
    A: float
    Iy: float
    Iz: float
    J: float
    Ip: float
    axes: np.ndarray
    length: float
    axial: bool = True
    torsion: bool = True
    kind: str = field(default="beam", init=False)

    @property
    def mass(self) -> float:
        """Total mass, kg."""
        return self.rho * self.A * self.length


@dataclass(frozen=True, eq=False)
class Model:
    """A validated model.

    points : name -> (3,) position, m.
    rigids, beams, springs : element records in file order.
    boundary : point name -> (6,) bool mask of fixed components
        (x, y, z, rx, ry, rz); points not listed are free.
    damping : (alpha, beta) of C = alpha M + beta K, or None.
    source : the file it came from (for messages), or None.
    """

    name: str
    points: dict[str, np.ndarray]
    rigids: tuple[Rigid, ...] = ()
    beams: tuple[Beam, ...] = ()
    springs: tuple[Spring, ...] = ()
    boundary: dict[str, np.ndarray] = field(default_factory=dict)
    damping: tuple[float, float] | None = None
    description: str = ""
    source: str | None = None

    @property
    def elements(self):
        """All elements: rigid bodies, then beams, then springs, each in file order."""
        return self.rigids + self.beams + self.springs

    def element(self, name: str):
        """The element called ``name`` (KeyError if none)."""
        for element in self.elements:
            if element.name == name:
                return element
        raise KeyError(name)

    def fixed_mask(self, point: str) -> np.ndarray:
        """(6,) bool: which displacement components are fixed at ``point``."""
        return self.boundary.get(point, np.zeros(6, dtype=bool))


def load_model(path) -> Model:
    """Read, validate and build the model in the TOML file ``path``.

    Raises :class:`ModelError` (one line: file, element, key) on any breach
    of the contract; nothing is built before validation is complete.
    """
    raise NotImplementedError
