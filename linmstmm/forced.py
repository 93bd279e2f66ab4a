"""Direct frequency response by the transfer matrix method, dashpots included.

At each excitation frequency Ω the transfer equations are solved in complex
arithmetic with the load as an inhomogeneous term, with no modes in between:

* a spring with dashpots has the complex stiffness k + iΩc in each direction
  (:func:`~linmstmm.elements.spring.damped_spring_transfer`);
* a point force F and moment T at a point make the internal force jump there:
  the state on the side towards the root is the state on the other side plus
  ``[0, 0, T, F]``. The jump enters the carry of the automatic deduction
  theorem as one more unknown, pinned to 1 by one more row
  (:meth:`linmstmm.deduction.Deduction.forced`), so the carry can be
  orthonormalised as for det Ū_all (it is where a beam's βL exceeds
  PLAIN_BETA_L) and the growing beam solutions cost no digits; the displacements at the response points are carried along (and
  rewritten by every orthonormalisation), and the extended Ū_all is solved
  (after equilibration);
* Rayleigh damping C = αM + βK (the model's ``[damping]``) is honoured
  exactly: the dynamic stiffness K(1 + iΩβ) + iΩC_d − (Ω² − iαΩ)M divided by
  1 + iΩβ is that of the undamped elements at the complex frequency
  ω̃ = √((Ω² − iαΩ) / (1 + iΩβ)) (every element matrix depends on ω² only),
  with dashpot rates iΩ / (1 + iΩβ), and the load divided by 1 + iΩβ.

Modal damping ratios have no meaning here (there are no modes): they belong
to the modal route (:mod:`linmstmm.response`).

Measured against the closed-form tip receptance of a steel cantilever
(tests/test_forced.py): within 1e-13 from βL = 1 to 185. Carried without the
orthonormalisation the same lost 4e-9 at βL ≈ 18, 1e-4 at βL ≈ 26, and all
digits beyond βL ≈ 35.
"""
from __future__ import annotations

import numpy as np

from linmstmm.deduction import Deduction
from linmstmm.elements.frames import FORCE_INDEX
from linmstmm.elements.spring import damped_spring_transfer
from linmstmm.model import COMPONENTS, Model, ModelError
from linmstmm.nullspace import equilibration, release_indeterminate
from linmstmm.response import FRFResult
from linmstmm.threads import single_blas_thread
from linmstmm.topology import Topology, build_topology

#: Frequencies solved together (bounds the memory of the Ū_all stacks).
CHUNK = 256
#: A chunk of frequencies at whose top every beam's βL (its largest wavenumber
#: times its length) is at most this is carried without orthonormalisation:
#: growth e^4 ≈ 55 costs under two digits (as a piece of the stable carry), and
#: the plain carry is then the more accurate (a cantilever loaded at the free
#: end of a spring pad, rooted at either end: 1e-14 apart plain, 1e-11
#: orthonormalised). Above it the orthonormalised carry keeps every digit.
PLAIN_BETA_L = 4.0


def has_dashpots(model: Model) -> bool:
    """Whether any spring of ``model`` has a nonzero dashpot ``c``.

    Parameters
    ----------
    model : Model
        The model.

    Returns
    -------
    bool
    """
    return any(spring.c is not None and np.any(spring.c > 0) for spring in model.springs)


def refuse_released_dashpots(model: Model) -> None:
    """ModelError (the spring, key ``c``) for a dashpot in a released direction of a joint.

    A released direction's jump is an unknown of its own whose force is zero
    (:func:`~linmstmm.elements.spring.joint_force`); a dashpot there would make
    that force iΩcΔ, which the direct route and the damped roots do not carry
    (the FE route's :func:`~linmstmm.fe.dashpot_matrix` would).

    Parameters
    ----------
    model : Model
        The model.
    """
    for spring in model.springs:
        if spring.c is None:
            continue
        damped = [COMPONENTS[d] for d in spring.released if spring.c[d] > 0]
        if damped:
            raise ModelError(model.source or model.name,
                             f"a dashpot in a released direction ({', '.join(damped)}) is not supported by "
                             f"the direct route and the damped roots: give c = 0 there", element=f"spring "
                             f"{spring.name!r}", key="c")


class DampedDeduction(Deduction):
    """The deduction of a topology whose springs with dashpots have complex stiffness.

    rate : (n,) complex, 1/s, the dashpot rate of each frequency of the stack
    the carry is given (iΩ for a harmonic motion at Ω): a spring with ``c`` has
    the stiffness k + rate c. Set it before each carry (it belongs to that
    stack). Periodic runs are not powered (cells that differ only in their
    dashpots would pass for equal). Everything else is :class:`Deduction`.
    """

    def __init__(self, topology: Topology, rate):
        super().__init__(topology)
        self.rate = np.asarray(rate, dtype=complex)

    def carried(self, e: int, omega, matrix) -> np.ndarray:
        """U_j @ matrix as :meth:`Deduction.carried`; a spring with dashpots complex."""
        record = self.topology.elements[e].record
        if getattr(record, "kind", None) == "spring" and record.c is not None:
            return damped_spring_transfer(record.k, record.c, record.axes, self.rate, record.release) @ matrix
        return super().carried(e, omega, matrix)

    def periodic_runs(self) -> list:
        """None: every cell is carried on its own."""
        return []


def released_deduction(topology: Topology) -> DampedDeduction:
    """A :class:`DampedDeduction` of ``topology`` with its statically indeterminate
    unknowns released (:func:`~linmstmm.nullspace.release_indeterminate`, found on
    the undamped system: they are the same), its ``rate`` still to be set."""
    plain = Deduction(topology)
    release_indeterminate(plain)
    damped = DampedDeduction(topology, np.zeros(0))
    damped.release(plain.released_columns, plain.released_rows)
    return damped


def rayleigh_equivalent(omega, damping):
    """The undamped problem equivalent to Rayleigh damping C = αM + βK at ``omega``.

    Parameters
    ----------
    omega : (n,) circular frequencies, rad/s, real or complex.
    damping : (α 1/s, β s) or None.

    Returns
    -------
    (carried, rate, factor), each (n,) complex: the elements' frequency
    ω̃ = √((ω² − iαω)/(1 + iωβ)), rad/s; the dashpots' rate iω/(1 + iωβ), 1/s;
    and 1 + iωβ, by which the dynamic stiffness was divided (a load is too).
    """
    alpha, beta = (0.0, 0.0) if damping is None else damping
    omega = np.asarray(omega, dtype=complex)
    factor = 1 + 1j * omega * beta
    return np.sqrt((omega**2 - 1j * alpha * omega) / factor), 1j * omega / factor, factor


def load_jumps(topology: Topology, point: str, vector) -> dict:
    """The jump of a point load, for :meth:`linmstmm.deduction.Deduction.forced`.

    Parameters
    ----------
    topology : the model's transfer structure.
    point : the loaded point.
    vector : (6,) or (n, 6) [force N, moment N m], inertial axes.

    Returns
    -------
    {(element, port): (12,) or (n, 12)}: one port at ``point`` (an element's
    output if there is one, else an input) and the jump of the state there.
    """
    vector = np.asarray(vector)
    jump = np.zeros(vector.shape[:-1] + (12,), dtype=vector.dtype)
    jump[..., FORCE_INDEX] = vector
    return {_port_at(topology, point, prefer_output=True): jump}


def _port_at(topology: Topology, point: str, prefer_output: bool) -> tuple[int, int]:
    """(element, port) of a port at ``point``: an element's output first if
    ``prefer_output`` (and there is one), else the first port found."""
    ports = [(e, p) for e, element in enumerate(topology.elements)
             for p, port in enumerate(element.ports) if port.point == point]
    outputs = [(e, p) for e, p in ports if p == topology.elements[e].output]
    return (outputs if prefer_output and outputs else ports)[0]


@single_blas_thread
def direct_frf(model: Model, point: str, vector, frequencies_hz, points=None, *,
               damping=None, root: str | None = None, orthonormalise: bool | None = None) -> FRFResult:
    """Receptance by the direct transfer-matrix solve, dashpots and Rayleigh damping exact.

    Parameters
    ----------
    model : Model
        The model; its springs' dashpots ``c`` act.
    point : str
        The loaded point.
    vector : array_like, shape (6,)
        The load [force N, moment N m] at ``point``, inertial axes.
    frequencies_hz : array_like, shape (n_f,)
        Excitation frequencies, Hz, > 0.
    points : sequence of str, optional
        Response points (default: every point of the model).
    damping : (float, float) or None
        (α 1/s, β s) of Rayleigh damping C = αM + βK added to the dashpots,
        or None (the model's ``[damping]`` is not read here: pass
        ``model.damping`` to use it).
    root : str or None
        Boundary end to use as the root of the transfer tree.
    orthonormalise : bool or None
        Carry with orthonormalisation (True), without (False), or by the
        beams' βL at the top of each chunk of frequencies (None: above
        PLAIN_BETA_L).

    Returns
    -------
    FRFResult
        :class:`linmstmm.response.FRFResult`: receptance (n_f, n_points, 6)
        complex, displacement (m) and rotation (rad) per unit of ``vector``.
        Exact for springs and rigid bodies, and for beams (continuous, no
        discretisation) to rounding.
    """
    refuse_released_dashpots(model)
    frequencies_hz = np.asarray(frequencies_hz, dtype=float)
    points = tuple(model.points) if points is None else tuple(points)
    topology = build_topology(model, root=root)
    deduction = released_deduction(topology)
    probes = {name: _port_at(topology, name, prefer_output=True) for name in points}
    receptance = np.zeros((frequencies_hz.size, len(points), 6), dtype=complex)
    for start in range(0, frequencies_hz.size, CHUNK):
        carried, deduction.rate, factor = rayleigh_equivalent(2 * np.pi * frequencies_hz[start:start + CHUNK],
                                                              damping)
        loads = np.asarray(vector, dtype=float) / factor[:, None]
        stable = _growing(model, carried) if orthonormalise is None else orthonormalise
        receptance[start:start + CHUNK] = _solve(deduction, carried, load_jumps(topology, point, loads), probes,
                                                 stable)
    return FRFResult(frequencies_hz, points, receptance)


def _growing(model: Model, omega) -> bool:
    """Whether some beam's βL exceeds PLAIN_BETA_L at the largest |ω| of ``omega`` (rad/s)."""
    top = float(np.max(np.abs(omega)))
    return any(max(beam.wavenumbers(top).values()) * beam.length > PLAIN_BETA_L for beam in model.beams)


def _solve(deduction: Deduction, omega, jumps, probes, stable: bool) -> np.ndarray:
    """(n, n_probes, 6) displacements at the ``probes`` under the loads ``jumps`` at ``omega`` (n,),
    the carry orthonormalised if ``stable``."""
    system, rhs, states = deduction.forced(omega, jumps, probes, stable)
    rows, cols = equilibration(system)
    scaled = rows[:, :, None] * system * cols[:, None, :]
    kept = cols * np.linalg.solve(scaled, (rows * rhs)[:, :, None])[:, :, 0]
    labels = deduction.full_order + len(jumps)
    unknowns = np.zeros((omega.size, labels), dtype=complex)
    unknowns[:, np.delete(np.arange(labels), deduction.released_columns)] = kept
    return np.stack([np.einsum("nik,nk->ni", state.matrix, unknowns[:, state.columns])
                     for state in states.values()], axis=1)
