"""Seeded random models with the extremes, for the FE cross-check at scale.

``varied_model(seed)`` draws one model from a numpy Generator. Most seeds take a
model of :func:`random_models.random_model` (trees, floating trees, loops,
floating loops, rings) and change it; some build a family of their own:

* ``strip``: one slender beam (A = 1e-5 to 1e-3 m²) clamped, pinned or free at
  each end, its bending stiffnesses 1 to 1e12 apart between the two planes;
* ``clamped body``: a rigid body held through one port by a zero-length spring
  to a fixed point (some directions ``inf``), with beams or springs and bodies
  hung on it;
* ``dangling only``: a rigid body fixed at a port, with springs whose far ends
  carry nothing (massless dangling points): no elastic mode at all;
* ``random``: a random model whose beams may be made slender (A down to
  1e-5 m², Iy/Iz up to 1e12 either way), with massless dangling points added.

Any of them may then be written in other units (:func:`in_units`: lengths in
mm or km, masses in g or t): the frequencies must not change. (:func:`in_units`
also scales time, which scales the frequencies: a slow copy of a model.)
:func:`varied_model` returns the model and a :class:`Variety` saying what was
drawn, so a report can name it.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from builders import fixed, make_beam, make_rigid, make_spring
from linmstmm.model import Model
from random_models import KINDS, random_direction, random_rotation, random_model

#: (label, length factor, mass factor): the same model in other units.
UNITS = (("m-kg-s", 1.0, 1.0), ("mm-kg-s", 1e3, 1.0), ("km-kg-s", 1e-3, 1.0),
         ("mm-t-s", 1e3, 1e-3), ("m-g-s", 1.0, 1e3))
FAMILIES = ("random", "strip", "clamped body", "dangling only")
#: Chances of the families, in FAMILIES order.
FAMILY_CHANCES = (0.7, 0.12, 0.12, 0.06)
#: Chance that a model is written in units other than SI.
OTHER_UNITS_CHANCE = 0.3
_BOUNDARIES = {"clamped": fixed(), "pinned": fixed("x", "y", "z"), "free": None}


@dataclass(frozen=True)
class Variety:
    """What :func:`varied_model` drew: family, base kind (random family), units label,
    and the extremes present (smallest beam area m², largest Iy/Iz or Iz/Iy,
    massless dangling points added)."""

    family: str
    kind: str
    units: str
    least_area: float
    largest_ratio: float
    dangling: int

    def label(self) -> str:
        """One line for a report."""
        kind = f" {self.kind}" if self.kind else ""
        return (f"{self.family}{kind}, {self.units}, A_min {self.least_area:.1e} m², "
                f"I ratio {self.largest_ratio:.1e}, {self.dangling} dangling")


def slender_section(rng: np.random.Generator, least_area: float = 1e-5) -> dict:
    """A beam section: A log-uniform in [least_area, 1e-3] m², second moments of a
    round bar of that area, one of Iy, Iz multiplied by 10^U(0, 12) (m⁴)."""
    area = 10 ** rng.uniform(np.log10(least_area), -3)
    round_bar = area ** 2 / (4 * np.pi)
    ratio = 10 ** rng.uniform(0, 12)
    stiff, soft = round_bar * ratio, round_bar
    Iy, Iz = (stiff, soft) if rng.random() < 0.5 else (soft, stiff)
    return dict(A=area, Iy=Iy, Iz=Iz, J=2 * round_bar, Ip=Iy + Iz)


def dangle(model: Model, rng: np.random.Generator, at: str) -> Model:
    """``model`` with a spring from point ``at`` to a new point that nothing else uses."""
    name = f"dangling{len(model.springs)}"
    points = {**model.points, name: model.points[at].copy()}
    k = np.r_[10 ** rng.uniform(3, 6, 3), 10 ** rng.uniform(1, 4, 3)]
    spring = make_spring(f"spring_{name}", at, name, k, random_rotation(rng))
    return dataclasses.replace(model, points=points, springs=model.springs + (spring,))


def in_units(model: Model, length: float, mass: float, time: float = 1.0) -> Model:
    """The same model written with lengths × ``length``, masses × ``mass`` and times ×
    ``time`` (its frequencies then come out ÷ ``time``).

    Derived units follow: Pa × mass/(length time²), kg/m³ × mass/length³, m² and m⁴
    × length² and length⁴, N/m × mass/time², N m/rad × mass length²/time², kg m² ×
    mass length².
    """
    force = mass * length / time ** 2
    beams = tuple(dataclasses.replace(
        b, E=b.E * force / length ** 2, G=b.G * force / length ** 2, rho=b.rho * mass / length ** 3,
        A=b.A * length ** 2, Iy=b.Iy * length ** 4, Iz=b.Iz * length ** 4, J=b.J * length ** 4,
        Ip=b.Ip * length ** 4, length=b.length * length) for b in model.beams)
    rigids = tuple(dataclasses.replace(r, mass=r.mass * mass, com=r.com * length,
                                       inertia=r.inertia * mass * length ** 2) for r in model.rigids)
    springs = tuple(dataclasses.replace(s, k=s.k * np.r_[[force / length] * 3, [force * length] * 3])
                    for s in model.springs)
    points = {p: x * length for p, x in model.points.items()}
    return dataclasses.replace(model, points=points, beams=beams, rigids=rigids, springs=springs)


def _strip(rng: np.random.Generator, name: str) -> Model:
    """One slender beam 0.5–3 m long, each end clamped, pinned or free (not both free
    half the time)."""
    length = rng.uniform(0.5, 3.0)
    points = {"a": np.zeros(3), "b": length * random_direction(rng)}
    ends = [str(e) for e in rng.choice(list(_BOUNDARIES), size=2)]
    if ends == ["free", "free"] and rng.random() < 0.5:
        ends[0] = "clamped"
    beam = make_beam("strip", "a", "b", points, y_hint=random_direction(rng), **slender_section(rng))
    boundary = {p: _BOUNDARIES[e] for p, e in zip("ab", ends) if _BOUNDARIES[e] is not None}
    return Model(name, points, beams=(beam,), boundary=boundary)


def _body(rng: np.random.Generator, name: str, port: str, points: dict) -> object:
    """A rigid body of 1–20 kg with its mass centre 0.05–0.3 m from ``port``."""
    mass = rng.uniform(1.0, 20.0)
    sides = rng.uniform(0.1, 0.5, 3)
    principal = mass / 12 * (np.sum(sides ** 2) - sides ** 2)
    rotation = random_rotation(rng)
    com = points[port] + rng.uniform(0.05, 0.3) * random_direction(rng)
    return make_rigid(name, [port], mass, com, rotation.T @ np.diag(principal) @ rotation)


def _clamped_body(rng: np.random.Generator, name: str) -> Model:
    """A body held through one port by a zero-length spring to a fixed point (a
    direction or two of it rigid), with a beam and a tip body, or another spring
    and body, hung on a second port."""
    points = {"ground": np.zeros(3), "hold": np.zeros(3), "arm": rng.uniform(-0.3, 0.3, 3)}
    k = np.r_[10 ** rng.uniform(4, 7, 3), 10 ** rng.uniform(2, 5, 3)]
    k[rng.choice(6, size=rng.integers(0, 3), replace=False)] = np.inf
    hold = make_spring("hold", "ground", "hold", k, random_rotation(rng))
    body = _body(rng, "body", "hold", points)
    body = dataclasses.replace(body, ports=("hold", "arm"))
    points["far"] = points["arm"] + rng.uniform(0.5, 2.0) * random_direction(rng)
    if rng.random() < 0.6:
        hung = make_beam("arm", "arm", "far", points, y_hint=random_direction(rng), **slender_section(rng, 1e-4))
        beams, springs = (hung,), (hold,)
    else:
        points["far"] = points["arm"].copy()
        beams, springs = (), (hold, make_spring("link", "arm", "far", np.r_[10 ** rng.uniform(3, 6, 3),
                                                                                10 ** rng.uniform(1, 4, 3)]))
    tip = _body(rng, "tip", "far", points)
    return Model(name, points, rigids=(body, tip), beams=beams, springs=springs,
                 boundary={"ground": fixed()})


def _dangling_only(rng: np.random.Generator, name: str) -> Model:
    """A rigid body fixed at its port, with one to three springs hanging free from it."""
    points = {"base": rng.uniform(-1, 1, 3)}
    model = Model(name, points, rigids=(_body(rng, "body", "base", points),), boundary={"base": fixed()})
    for _ in range(int(rng.integers(1, 4))):
        model = dangle(model, rng, "base")
    return model


def _varied_random(rng: np.random.Generator, kind: str, seed: int, name: str) -> tuple[Model, int]:
    """A random model of ``kind`` with slender beams (half the time) and 0–2
    massless dangling points; (model, dangling points added)."""
    model = dataclasses.replace(random_model(kind, seed), name=name)
    if model.beams and rng.random() < 0.5:
        beams = tuple(dataclasses.replace(b, **slender_section(rng)) if rng.random() < 0.6 else b
                      for b in model.beams)
        model = dataclasses.replace(model, beams=beams)
    added = int(rng.choice(3, p=(0.6, 0.3, 0.1)))
    for _ in range(added):
        model = dangle(model, rng, str(rng.choice(list(model.points))))
    return model, added


def varied_model(seed: int, family: str | None = None, units: str | None = None) -> tuple[Model, Variety]:
    """A random model with the extremes (see the module notes), reproducible from
    ``seed``; ``family`` and ``units`` (labels of FAMILIES and UNITS) force a
    choice. Returns (model, what was drawn)."""
    rng = np.random.default_rng([1234, seed])
    drawn_family = str(rng.choice(FAMILIES, p=FAMILY_CHANCES))
    drawn_units = UNITS[int(rng.integers(1, len(UNITS)))][0] if rng.random() < OTHER_UNITS_CHANCE else UNITS[0][0]
    family, units = family or drawn_family, units or drawn_units
    kind, added, name = "", 0, f"varied {seed}"
    if family == "random":
        kind = KINDS[seed % len(KINDS)]
        model, added = _varied_random(rng, kind, seed, name)
    elif family == "strip":
        model = _strip(rng, name)
    elif family == "clamped body":
        model = _clamped_body(rng, name)
    else:
        model = _dangling_only(rng, name)
        added = len(model.springs)
    _, length, mass = next(u for u in UNITS if u[0] == units)
    variety = Variety(family, kind, units, min((b.A for b in model.beams), default=np.nan),
                      max((max(b.Iy / b.Iz, b.Iz / b.Iy) for b in model.beams), default=np.nan), added)
    return in_units(model, length, mass), variety
