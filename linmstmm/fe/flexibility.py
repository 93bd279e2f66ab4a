"""The flexibility ``K⁺``: static response by the mixed (force–displacement)
system on the natural factor, rigid-body modes deflated; static displacements
under point loads."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from linmstmm.fe.assembly import FEModel, assemble
from linmstmm.model import Model


class _Flexibility:
    """``f -> P K⁺ Pᵀ f``: static response to loads, rigid-body modes deflated.

    K is never factorised: the solve uses the mixed system
    ``[[-D⁻¹, G], [Gᵀ, 0]] [s; y] = [0; f]`` (s = element forces) on the DOFs
    left free by the temporary supports. ``P = I - R Rᵀ M`` removes the
    rigid-body modes R, so ``K⁺M`` has eigenvalues 1/λ for elastic modes and
    0 for rigid-body modes and massless DOFs.
    """

    def __init__(self, fe: FEModel):
        self.fe = fe
        self.free = np.setdiff1d(np.arange(fe.n_dof), fe.supports)
        self.n_strain = len(fe.D)
        self.lu = None
        if len(self.free):
            g = fe.G[:, self.free]
            mixed = sp.bmat([[sp.diags(-1.0 / fe.D), g], [g.T, None]], format="csc")
            try:
                self.lu = splu(mixed)
            except RuntimeError as error:
                raise ValueError(
                    f"{fe.n_dof}-DOF model: the stiffness is singular beyond its rigid-body "
                    f"modes (a motion with neither stiffness nor support): {error}") from None

    def __call__(self, f: np.ndarray) -> np.ndarray:
        """f : (n_dof,) or (n_dof, b) loads; returns displacements of the same shape."""
        return self.solve(np.asarray(f, float).reshape(self.fe.n_dof, -1))[0].reshape(np.shape(f))

    def solve(self, loads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Displacements and energy-weighted strains under ``loads``.

        Parameters
        ----------
        loads : (n_dof, b) forces (N) and moments (N m).

        Returns
        -------
        y : (n_dof, b) displacements (m, rad), rigid-body modes deflated.
        strains : (n_strain, b) ``D^½ G y`` (√(N m)): the strain energy of y
            is ``½ |strains|²``.

        The strains are those of the displacements on the temporary supports,
        before the rigid-body modes are deflated, which leaves them unchanged
        (a rigid motion strains nothing). Taken after, they would take in the
        rounding of the rigid-body modes: those are stored to the rounding of
        their translations (the model's extent times their rotation), and
        each element's chord rotation (w₂ − w₁)/h carries that rounding 1/h
        larger, at the stiffness of the element. On 1024 elements per beam of
        a floating loop with a beam whose bending planes are 7e10 apart, the
        rigid-body modes so computed held a strain energy of 1e-2 of the
        second elastic λ, and its Rayleigh quotient came out 3e-9 high.
        """
        fe, modes = self.fe, self.fe.rigid_modes
        loads = loads - fe.M @ (modes @ (modes.T @ loads))
        y = np.zeros_like(loads)
        if self.lu is not None:
            rhs = np.zeros((self.n_strain + len(self.free), loads.shape[1]))
            rhs[self.n_strain:] = loads[self.free]
            y[self.free] = self.lu.solve(rhs)[self.n_strain:]
        strains = np.sqrt(fe.D)[:, None] * (fe.G @ y)
        y -= modes @ (modes.T @ (fe.M @ y))
        return y, strains


def static_displacements(model: Model, loads, points, elements_per_beam: int = 1) -> np.ndarray:
    """Elastic static displacements of ``points`` under each point load, K⁺ f.

    Hermite beam elements give the exact static solution at their nodes for
    point loads, so one element per beam suffices for a held model. A model
    with rigid-body modes is solved for its elastic part: the load's
    rigid-body part is removed and so is the rigid-body motion of the result
    (M-orthogonal to the rigid-body modes, as the elastic modes are); that
    last step weighs the beams' interpolated fields with the mesh's mass, so
    with beams it converges with the mesh instead of being exact.

    Parameters
    ----------
    model : the model records.
    loads : sequence of (point name, (6,) [force N, moment N m]) in inertial axes.
    points : sequence of point names to report.
    elements_per_beam : int >= 1.

    Returns
    -------
    (n_loads, n_points, 6) displacements m and rotations rad, inertial axes.
    """
    fe = assemble(model, elements_per_beam)
    full = np.zeros((fe.n_full, len(loads)))
    for i, (point, vector) in enumerate(loads):
        full[fe.dof_index.point(point), i] = vector
    motion = (fe.T @ _Flexibility(fe)(fe.T.T @ full)).T  # (n_loads, n_full)
    return np.stack([motion[:, fe.dof_index.point(p)] for p in points], axis=1)
