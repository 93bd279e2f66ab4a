"""Masses negligible against the model's own scale, removed before assembly so
that a massless DOF has an exactly zero row and column in M."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.linalg as la

from linmstmm.model import Model, Rigid

#: A mass (kg), inertia (kg m²) or kinetic energy below this fraction of the
#: model's own scale of the same units is rounding, not mass: a body's mass or
#: principal inertia, a beam, or a rigid motion below it carries none.
MASSLESS = 1e-13
#: A least principal inertia above this many times the negligible one is kept
#: whatever the rounding of the eigensolver that found it (:func:`_maybe_negligible`).
SURE_INERTIA = 2.0


def _negligible_mass_removed(model: Model, places: np.ndarray | None = None) -> Model:
    """``model`` with every mass below MASSLESS of the model's own scale set to zero.
    ``places``: its points then its mass centres, (n, 3) m, where the caller has them
    (a layout's positions), else gathered here.

    The scales are the total mass m of bodies and beams (kg) and m d² plus the
    traces of the bodies' inertia tensors (kg m²), d the largest distance of a
    point or mass centre from their centroid (m). Each body's mass and principal
    inertias and each beam's mass are compared with the scale of their units, so
    the decision does not depend on the units a model is written in; a mass that
    is kept is exactly as given. A DOF without mass then has an exactly zero row
    and column in the assembled M.
    """
    if places is None:
        places = np.array([*model.points.values(), *(body.com for body in model.rigids)], float)
    arms = places - np.add.reduce(places, axis=0) / len(places)     # from the mean, as numpy's mean forms it
    extent = np.sqrt(np.add.reduce(arms * arms, axis=1).max())      # the largest norm, as numpy's norm forms it
    masses = np.array([body.mass for body in model.rigids], float)
    tensors = np.array([body.inertia for body in model.rigids], float).reshape(-1, 3, 3)
    total = sum(masses.tolist()) + sum(beam.mass for beam in model.beams)
    inertia = total * extent ** 2 + sum(np.trace(tensors, axis1=1, axis2=2).tolist())
    looked_at = _maybe_negligible(masses, tensors, MASSLESS * total, MASSLESS * inertia).tolist()
    rigids = tuple(_body_mass_kept(body, MASSLESS * total, MASSLESS * inertia) if look else body
                   for body, look in zip(model.rigids, looked_at))
    beams = tuple(beam if beam.mass > MASSLESS * total else replace(beam, rho=0.0) for beam in model.beams)
    if all(a is b for a, b in zip(rigids + beams, model.rigids + model.beams)):
        return model  # nothing negligible: no copy (a copy validates the whole model again)
    return replace(model, rigids=rigids, beams=beams)


def _maybe_negligible(masses: np.ndarray, tensors: np.ndarray, least_mass: float, least_inertia: float) -> np.ndarray:
    """(b,) bool: the bodies (masses (b,) kg, inertia tensors (b, 3, 3) kg m²) that
    :func:`_body_mass_kept` may change; the others it returns as they are.

    Where Gershgorin's bound cannot clear a tensor, its least principal inertia
    can (all of them in one call, where :func:`_body_mass_kept` takes one LAPACK
    call per body): above SURE_INERTIA times ``least_inertia`` it is above
    ``least_inertia`` in any backward-stable solver's rounding too (a few eps of
    the tensor's norm, at most its trace, itself at most 1e13 ``least_inertia``).
    """
    diagonal = tensors.diagonal(axis1=1, axis2=2)
    gershgorin = diagonal - (np.abs(tensors).sum(axis=2) - np.abs(diagonal))
    light = (masses != 0) & (masses <= least_mass)
    doubtful = diagonal.any(axis=1) & (gershgorin.min(axis=1, initial=np.inf) <= least_inertia)
    if doubtful.any():
        doubtful[doubtful] = np.linalg.eigvalsh(tensors[doubtful])[:, 0] <= SURE_INERTIA * least_inertia
    return light | doubtful


def _body_mass_kept(body: Rigid, least_mass: float, least_inertia: float) -> Rigid:
    """``body`` with its mass (kg) made zero unless above ``least_mass``, and its
    principal inertias (kg m²) unless above ``least_inertia``; the same record when
    nothing changes."""
    mass = body.mass if body.mass > least_mass else 0.0
    inertia, diagonal = body.inertia, body.inertia.diagonal()
    # Gershgorin: the least of these is at most the smallest principal inertia
    gershgorin = diagonal - (np.abs(inertia).sum(axis=1) - np.abs(diagonal))
    if diagonal.any() and gershgorin.min() <= least_inertia:
        principal, axes = la.eigh(inertia)
        kept = principal > least_inertia
        if not np.all(kept | (principal == 0.0)):
            inertia = (axes * np.where(kept, principal, 0.0)) @ axes.T
    if mass == body.mass and inertia is body.inertia:
        return body
    return replace(body, mass=mass, inertia=inertia)
