"""Build model records in Python, without a TOML file.

The constructors here make the same immutable records as
:func:`linmstmm.model.load_model` (:class:`~linmstmm.model.Beam`,
:class:`~linmstmm.model.Rigid`, :class:`~linmstmm.model.Spring`,
:class:`~linmstmm.model.Model`), for scripts and tests that generate models.
They do not validate: a model built here is taken as given, so keep to the
limits of ``docs/model-format.md`` (positive stiffnesses, coinciding spring
ends, a model with mass).

Units are SI throughout: m, kg, s, N, rad, Pa.

Example
-------
>>> from linmstmm.builders import fixed, single_beam_model
>>> model = single_beam_model(left=fixed(), length=2.0)
>>> model.beams[0].length
2.0
"""
from __future__ import annotations

import numpy as np

from linmstmm.geometry import local_axes, norm3
from linmstmm.model import COMPONENTS, Beam, Model, Rigid, Spring

#: Structural steel: E and G in Pa, rho in kg/m^3.
STEEL = dict(E=2.1e11, G=8.1e10, rho=7850.0)


def beam_axes(a, b, y_hint=None) -> np.ndarray:
    """Local axes of a beam from ``a`` to ``b``, by the model format's rule
    (:func:`linmstmm.geometry.local_axes`, as the loader forms them).

    Parameters
    ----------
    a, b : array_like, shape (3,)
        End positions, m, inertial frame (local x runs from a to b).
    y_hint : array_like, shape (3,), optional
        Direction of local y before it is made normal to x (a file's ``y_axis``).
        Default e_Z × x, or e_Y where the beam is vertical.

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        Rows: local x, y, z unit vectors in the inertial frame (right-handed).

    Raises
    ------
    ValueError
        Where ``y_hint`` is zero or parallel to the beam.
    """
    along = np.asarray(b, float) - np.asarray(a, float)
    hint = None if y_hint is None else np.asarray(y_hint, float)
    if hint is not None and (size := norm3(hint)) > 0:
        # unit length first: the same direction, and the frames built so far to the bit (tests pin them)
        hint = hint / size
    return local_axes(along / norm3(along), hint)


def make_beam(name, a, b, points, A=1e-3, Iy=2e-7, Iz=2e-7, J=4e-7, Ip=None, y_hint=None,
              material=STEEL, **options) -> Beam:
    """A straight uniform Euler-Bernoulli beam between two named points.

    Parameters
    ----------
    name : str
        Element name.
    a, b : str
        End point names; local x runs from ``a`` to ``b``.
    points : dict of str to array_like, shape (3,)
        Point positions, m (must hold ``a`` and ``b``).
    A : float
        Cross-section area, m^2.
    Iy, Iz : float
        Second moments of area about local y and z, m^4.
    J : float
        Torsion constant, m^4.
    Ip : float, optional
        Polar second moment for the torsional inertia rho Ip, m^4; default Iy + Iz.
    y_hint : array_like, shape (3,), optional
        Direction of local y (see :func:`beam_axes`).
    material : dict
        ``E`` and ``G`` in Pa, ``rho`` in kg/m^3; default :data:`STEEL`.
    **options
        ``axial=False`` / ``torsion=False``: rigid in that deformation.

    Returns
    -------
    linmstmm.model.Beam
    """
    pa, pb = np.asarray(points[a], float), np.asarray(points[b], float)
    return Beam(name, (a, b), material["E"], material["G"], material["rho"], A, Iy, Iz, J,
                Iy + Iz if Ip is None else Ip, beam_axes(pa, pb, y_hint),
                float(np.linalg.norm(pb - pa)), **options)


def make_rigid(name, ports, mass, com, inertia=(0.0, 0.0, 0.0)) -> Rigid:
    """A rigid body.

    Parameters
    ----------
    name : str
        Element name.
    ports : sequence of str
        Names of the points on the body (one or more).
    mass : float
        Mass, kg (>= 0).
    com : array_like, shape (3,)
        Mass centre, m, inertial frame.
    inertia : array_like, shape (3,) or (3, 3)
        About the mass centre, inertial axes, kg m^2: the diagonal
        [Ixx, Iyy, Izz] or the full symmetric tensor. Default: a point mass.

    Returns
    -------
    linmstmm.model.Rigid
    """
    inertia = np.asarray(inertia, float)
    return Rigid(name, tuple(ports), mass, np.asarray(com, float),
                 np.diag(inertia) if inertia.ndim == 1 else inertia)


def make_spring(name, a, b, k, axes=None, release=()) -> Spring:
    """An elastic hinge (massless, zero length) between two coinciding points.

    Parameters
    ----------
    name : str
        Element name.
    a, b : str
        End point names (the points must coincide).
    k : array_like, shape (6,)
        [kx, ky, kz, krx, kry, krz] in the spring's axes: N/m and N m/rad,
        each > 0 (exactly 0 where released); ``numpy.inf`` = rigid in that direction.
    axes : array_like, shape (3, 3), optional
        Rows: the spring's local x, y, z unit vectors; default the inertial axes.
    release : sequence of str, optional
        Released directions drawn from "x", "y", "z", "rx", "ry", "rz" (in the
        spring's axes): a joint, no force or moment there.

    Returns
    -------
    linmstmm.model.Spring
    """
    mask = np.array([c in release for c in COMPONENTS])
    return Spring(name, (a, b), np.asarray(k, float), np.eye(3) if axes is None else np.asarray(axes),
                  release=mask if mask.any() else None)


def fixed(*components) -> np.ndarray:
    """A boundary mask: which displacement components are held at a point.

    Parameters
    ----------
    *components : str
        Names drawn from "x", "y", "z", "rx", "ry", "rz"; none = all six (fixed).

    Returns
    -------
    numpy.ndarray, shape (6,), bool
        In the order x, y, z, rx, ry, rz.
    """
    return np.array([not components or name in components for name in COMPONENTS])


def single_beam_model(left=None, right=None, length=2.0, **beam_options) -> Model:
    """One beam along x from point "a" (at the origin) to point "b".

    Parameters
    ----------
    left, right : numpy.ndarray, shape (6,), bool, optional
        Boundary masks (see :func:`fixed`) of "a" and "b"; None = free.
    length : float
        Beam length, m.
    **beam_options
        Passed to :func:`make_beam` (section, material, ``axial``, ``torsion``).

    Returns
    -------
    linmstmm.model.Model
    """
    points = {"a": np.zeros(3), "b": np.array([length, 0.0, 0.0])}
    boundary = {p: mask for p, mask in (("a", left), ("b", right)) if mask is not None}
    return Model("beam", points, beams=(make_beam("beam", "a", "b", points, **beam_options),),
                 boundary=boundary)


def spring_mass_chain(k=1000.0, m=2.0, damping=None) -> Model:
    """Two masses between three springs along x: fixed - k - 3m - k - m - k - fixed.

    Rotations are locked by rigid rotational springs, so every translation
    direction repeats the one-dimensional chain, whose natural circular
    frequencies are ω² = (4 ∓ √7)/3 · k/m, each three times.

    Parameters
    ----------
    k : float
        Translational stiffness of each spring, N/m.
    m : float
        Mass of the lighter body, kg (the other has 3 m).
    damping : tuple of float, optional
        The model's (alpha, beta) of C = alpha M + beta K (1/s, s), or None.

    Returns
    -------
    linmstmm.model.Model
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


def spring_chain(n: int, m: float = 1.0, k: float = 1e6) -> Model:
    """ground–k–m–k–m–…–m (fixed–free), ``n`` bodies of 1 m spacing.

    Isotropic translational springs, rotations locked by rigid rotational
    springs: every direction repeats the 1-D chain, whose natural circular
    frequencies are ω_j = 2 √(k/m) sin((2j − 1) π / (2 (2n + 1))), each three
    times. A model of any length made of one repeated cell (2n elements).

    Parameters
    ----------
    n : int
        Number of bodies.
    m : float
        Mass of each body, kg (a point mass: no rotary inertia).
    k : float
        Translational stiffness of each spring, N/m.

    Returns
    -------
    linmstmm.model.Model
    """
    points = {"g": np.zeros(3)}
    rigids, springs = [], []
    for i in range(n):
        points[f"a{i}"] = np.array([float(i), 0.0, 0.0])
        points[f"b{i}"] = np.array([i + 1.0, 0.0, 0.0])
        before = "g" if i == 0 else f"b{i - 1}"
        springs.append(Spring(f"k{i}", (before, f"a{i}"), np.array([k, k, k, np.inf, np.inf, np.inf]),
                              np.eye(3)))
        rigids.append(Rigid(f"m{i}", (f"a{i}", f"b{i}"), m, np.array([i + 0.5, 0.0, 0.0]),
                            np.zeros((3, 3))))
    return Model(f"spring-mass chain N={n}", points, rigids=tuple(rigids), springs=tuple(springs),
                 boundary={"g": np.ones(6, dtype=bool)})


#: The six directions of an octahedral star's arms (:func:`beam_star`).
OCTAHEDRAL = ((1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0))


def beam_star(beams_per_arm: int, gap: float = 0.0, directions=OCTAHEDRAL, length: float = 1.0) -> Model:
    """Steel arms of beams from a free centre, each arm's far end clamped: a model whose
    roots come in clusters.

    Each section has Iy = 2e-7 m⁴ and Iz = Iy (1 + ``gap``)², A = 1e-3 m², J = Ip = 4e-7 m⁴.
    With ``gap`` 0 and the six octahedral arms, symmetry makes the bending roots
    multiple; a small ``gap`` parts them into clusters about gap / 2 wide (relative),
    with double roots where arms mirror each other. Cutting each arm into more beams
    changes no natural frequency, only the size of the model: one beam an arm has a
    Wittrick–Williams counter at every root, twenty (690 unknowns) do not.

    Parameters
    ----------
    beams_per_arm : int
        Equal beams each arm is cut into.
    gap : float
        Relative gap between the bending planes' √I (0: equal).
    directions : sequence of 3-sequences
        The arms' directions (unit vectors); the octahedral six by default.
    length : float
        Length of each arm, m.

    Returns
    -------
    linmstmm.model.Model
    """
    points, beams, boundary = {"centre": np.zeros(3)}, [], {}
    for arm, direction in enumerate(directions):
        previous = "centre"
        for k in range(1, beams_per_arm + 1):
            name = f"arm{arm}_{k}"
            points[name] = np.asarray(direction, dtype=float) * length * k / beams_per_arm
            beams.append(make_beam(f"beam{arm}_{k}", previous, name, points, Iy=2e-7, Iz=2e-7 * (1 + gap) ** 2,
                                   J=4e-7, Ip=4e-7))
            previous = name
        boundary[previous] = fixed()
    return Model(f"star of {len(directions)} arms, {beams_per_arm} beams each, planes {gap:g} apart", points,
                 beams=tuple(beams), boundary=boundary)
