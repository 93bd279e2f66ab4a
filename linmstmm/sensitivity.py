"""Derivatives of natural frequencies with respect to model values, from the mode shapes.

For a mass-normalised mode φ at ω, ∂(ω²)/∂p = φᵀ (∂K/∂p − ω² ∂M/∂p) φ: the
derivatives of the elements' strain and kinetic energies in the mode, with
the mode held fixed. No finite differences; each term is a closed form in the
mode's values:

* rigid body (mass m, mass centre c, inertia J_c; u_c and θ the mode's
  translation of the mass centre and rotation): ∂M/∂m → |u_c|²,
  ∂M/∂J_ij → θ_i θ_j (both symmetric entries), ∂M/∂c_i → 2 m u_c·(θ × e_i)
  (u_c = u_p + θ × (c − p) moves with c);
* spring: ∂K/∂k_i → Δ_i², Δ = the relative displacement of its ends in its
  axes; dashpots and ``[damping]`` do not change the undamped frequencies (0);
* beam: the energy integrals along the beam of the transfer-matrix mode
  itself (not an interpolation of its end values): the state at the beam's
  first end is carried to Gauss–Legendre nodes by the exact beam transfer
  matrix, and curvatures κ = m/EI, axial strain q/EA, twist m_x/GJ,
  translations and torsional rotation are integrated; e.g.
  ∂K/∂E → I_y ∫κ_y² + I_z ∫κ_z² + A ∫ε², ∂M/∂ρ → A ∫|u|² + I_p ∫θ_x².

A repeated frequency splits under most changes: within its eigenspace the
derivatives are the eigenvalues of the small matrix Φᵀ(∂K − ω²∂M)Φ, given in
ascending order (the order of the ranks for an increasing value). Point
coordinates and spring axes move the geometry and have no such closed form:
they are refused.
"""
from __future__ import annotations

import numpy as np

from linmstmm.eigenspaces import SAME_FREQUENCY
from linmstmm.elements.beam import beam_states, beam_transfer
from linmstmm.mode_fields import quadrature
from linmstmm.model import Model, ModelError
from linmstmm.modes import ModalResult
from linmstmm.parameters import Key, parse_key


def frequency_sensitivities(model: Model, modes: ModalResult, keys) -> dict[str, np.ndarray]:
    """∂f/∂value of each elastic mode of ``modes`` for every key in ``keys``.

    Parameters
    ----------
    model : Model
        The model.
    modes : ModalResult
        Mass-normalised modes of ``model`` (:func:`linmstmm.modes.mode_shapes`
        with the default normalisation), rigid-body modes left out or included
        (their rows are 0).
    keys : iterable of str
        Key strings (:mod:`linmstmm.parameters`).

    Returns
    -------
    dict of str to ndarray
        key -> (n,) Hz per SI unit of the key, in the order of ``modes``.

    Raises
    ------
    ModelError
        For a key without a closed-form derivative (points, spring axes).
    ValueError
        For modes that are not mass-normalised.
    """
    if modes.normalization != "mass":
        raise ValueError("sensitivities need mass-normalised modes (normalization='mass')")
    parsed = [parse_key(model, text) for text in keys]
    beams = {}
    out = {}
    for key in parsed:
        if key.section == "beam" and key.name not in beams:
            beams[key.name] = _beam_integrals(model.element(key.name), modes)
        form = _form(model, modes, key, beams.get(key.name))
        out[key.text] = _per_mode(form, modes.omega)
    return out


def _per_mode(form: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """(n,) ∂f/∂p from the (n, n) form Φᵀ(∂K − ω²∂M)Φ, eigenspace by eigenspace."""
    derivative = np.zeros(omega.size)
    start = 0
    while start < omega.size:
        stop = start + 1
        while stop < omega.size and abs(omega[stop] - omega[start]) <= SAME_FREQUENCY * omega[start]:
            stop += 1
        block = form[start:stop, start:stop]
        derivative[start:stop] = np.linalg.eigvalsh((block + block.T) / 2)
        start = stop
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(omega > 0, derivative / (2 * omega) / (2 * np.pi), 0.0)


def _form(model: Model, modes: ModalResult, key: Key, beam_integrals) -> np.ndarray:
    """(n, n) Φᵀ(∂K/∂p − ω² ∂M/∂p)Φ for ``key`` (ω² of the row's mode)."""
    w2 = modes.omega[:, None] ** 2
    if key.section == "rigid":
        return -w2 * _rigid_mass_form(model.element(key.name), modes, key)
    if key.section == "spring" and key.field == "k":
        return _spring_form(model.element(key.name), modes, key.index[0])
    if (key.section == "spring" and key.field == "c") or key.section == "damping":
        return np.zeros((modes.omega.size,) * 2)
    if key.section == "beam":
        return _beam_form(model.element(key.name), beam_integrals, key.field, w2)
    raise ModelError(model.source or f"model {model.name!r}",
                     "moves the geometry: no closed-form sensitivity (only masses, inertias, "
                     "mass centres, stiffnesses and section values have one)", key=key.text)


def _outer(a: np.ndarray, b: np.ndarray | None = None) -> np.ndarray:
    """(n, n) Σ_d a[k, d] b[l, d] for (n, d) arrays (b defaults to a)."""
    a = a.reshape(a.shape[0], -1)
    b = a if b is None else b.reshape(b.shape[0], -1)
    return a @ b.T


def _rigid_mass_form(rigid, modes: ModalResult, key: Key) -> np.ndarray:
    """(n, n) Φᵀ ∂M/∂p Φ of a rigid body's mass, inertia entry or mass-centre coordinate."""
    motion = modes.com_displacements[rigid.name]
    translation, rotation = motion[:, :3], motion[:, 3:]
    if key.field == "mass":
        return _outer(translation)
    if key.field == "inertia":
        i, j = key.index
        form = _outer(rotation[:, [i]], rotation[:, [j]])
        return form + form.T if i != j else form
    moved = np.cross(rotation, np.eye(3)[key.index[0]])  # ∂u_c/∂c_i = θ × e_i
    form = rigid.mass * _outer(moved, translation)
    return form + form.T


def _spring_form(spring, modes: ModalResult, component: int) -> np.ndarray:
    """(n, n) Φᵀ ∂K/∂k_i Φ: products of the ends' relative displacement along local ``component``."""
    if spring.release is not None and spring.release[component]:  # a joint: k there does not act
        return np.zeros((modes.omega.size,) * 2)
    a, b = (modes.point_displacements[p] for p in spring.ends)
    delta = b - a
    axes = np.asarray(spring.axes, float)
    local = delta[:, :3] @ axes.T if component < 3 else delta[:, 3:] @ axes.T
    return _outer(local[:, [component % 3]])


def _beam_form(beam, integrals: dict, field: str, w2: np.ndarray) -> np.ndarray:
    """(n, n) Φᵀ(∂K/∂p − ω² ∂M/∂p)Φ of one section value of ``beam`` from its energy integrals."""
    I = integrals
    stiffness = {"E": beam.Iy * I["curvature_y"] + beam.Iz * I["curvature_z"] + beam.A * I["strain"],
                 "Iy": beam.E * I["curvature_y"], "Iz": beam.E * I["curvature_z"],
                 "G": beam.J * I["twist"], "J": beam.G * I["twist"], "A": beam.E * I["strain"]}
    mass = {"rho": beam.A * I["translation"] + beam.Ip * I["torsion"],
            "A": beam.rho * I["translation"], "Ip": beam.rho * I["torsion"]}
    zero = np.zeros_like(w2 * w2.T)
    return stiffness.get(field, zero) - w2 * mass.get(field, zero)


def _beam_integrals(beam, modes: ModalResult) -> dict[str, np.ndarray]:
    """(n, n) integrals along ``beam`` of products of the modes' curvatures (1/m), axial strain,
    twist (1/m), translations (m) and torsional rotation: the exact transfer-matrix field."""
    omega = modes.omega
    start = _start_state(beam, modes)
    nodes, weights = quadrature(beam, omega.max(initial=0.0))
    axes = np.asarray(beam.axes, float)
    states = beam_states(beam, omega, start, nodes)  # (n, q, 12), local values below
    translation, rotation = states[..., 0:3] @ axes.T, states[..., 3:6] @ axes.T
    moment, force = states[..., 6:9] @ axes.T, states[..., 9:12] @ axes.T
    root = np.sqrt(weights)

    def integral(values):  # (n, q) or (n, q, 3) values at the nodes
        return _outer(values * root.reshape((-1,) + (1,) * (values.ndim - 2)))

    fields = {"curvature_y": integral(moment[..., 1] / (beam.E * beam.Iy)),
              "curvature_z": integral(moment[..., 2] / (beam.E * beam.Iz)),
              "translation": integral(translation), "torsion": integral(rotation[..., 0])}
    none = np.zeros((omega.size, omega.size))
    fields["strain"] = integral(force[..., 0] / (beam.E * beam.A)) if beam.axial else none
    fields["twist"] = integral(moment[..., 0] / (beam.G * beam.J)) if beam.torsion else none
    return fields


def _start_state(beam, modes: ModalResult) -> np.ndarray:
    """(n, 12) state of every mode at ``ends[0]`` with the forces of transfer towards ``ends[1]``.

    The modes' port states give each force as the element's upstream side exerts it
    downstream; the beam was traversed one way or the other, so the end states are
    taken as given or with both ends' forces reversed, whichever the exact transfer
    over the beam carries from ``ends[0]`` to ``ends[1]``.
    """
    first, second = (modes.port_states[f"{beam.name}@{p}"] for p in beam.ends)
    transfer = beam_transfer(beam, modes.omega)
    flip = np.concatenate([np.ones(6), -np.ones(6)])
    candidates = [(first, second), (first * flip, second * flip)]
    misfit = [np.linalg.norm(np.einsum("nij,nj->ni", transfer, a) - b) for a, b in candidates]
    return candidates[int(np.argmin(misfit))][0]
