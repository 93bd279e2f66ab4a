"""The beams' clamped-end mode count J0 (Wittrick and Williams) bounds the natural
frequencies below ω from below; a range request it puts beyond MAX_RANGE_MODES is refused."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize
from builders import STEEL, fixed, single_beam_model

from linmstmm.fe import fe_frequencies
from linmstmm.mode_bound import MAX_RANGE_MODES, check_range_request, clamped_modes_below
from linmstmm.model import ModelError, load_model
from linmstmm.solve import natural_frequencies

ROOT = Path(__file__).resolve().parents[1]
SECTION = dict(A=1e-3, Iy=2e-7, Iz=5e-7, J=4e-7, Ip=7e-7)


def clamped_clamped_count(omega: float, length: float) -> int:
    """Frequencies below ``omega`` (rad/s) of a clamped–clamped steel beam with SECTION,
    from the closed forms: bending cosh λ cos λ = 1 (one root in each ((k + ½)π ± 0.1)
    for k >= 1), axial and torsion kπc/L."""
    E, G, rho = STEEL["E"], STEEL["G"], STEEL["rho"]
    total = 0
    for I in (SECTION["Iy"], SECTION["Iz"]):
        beta_L = (rho * SECTION["A"] * omega ** 2 / (E * I)) ** 0.25 * length
        roots = [scipy.optimize.brentq(lambda x: math.cos(x) - 1 / math.cosh(x), (k + 0.5) * math.pi - 0.1,
                                       (k + 0.5) * math.pi + 0.1) for k in range(1, int(beta_L / math.pi) + 2)]
        total += sum(root < beta_L for root in roots)
    for speed in (math.sqrt(E / rho), math.sqrt(G * SECTION["J"] / (rho * SECTION["Ip"]))):
        total += math.ceil(omega * length / (math.pi * speed)) - 1
    return total


@pytest.mark.parametrize("omega", [50.0, 3e3, 2e4, 1.3e5, 7e5])
def test_one_clamped_beam_counts_its_closed_forms(omega):
    """One element clamped at both ends: J = J0, counted exactly (the roots of
    cos βL = 1/cosh βL per bending plane, kπc/L per rod)."""
    model = single_beam_model(left=fixed(), right=fixed(), length=2.0, **SECTION)
    assert clamped_modes_below(model, omega) == clamped_clamped_count(omega, 2.0)


def test_the_bound_holds_for_the_launcher_against_finite_elements():
    """The MLRS model's 40 lowest frequencies by the FE route: below each, at least as
    many as the bound says (the bodies and springs add their own: J0 only bounds J)."""
    model = load_model(ROOT / "models" / "mlrs" / "mlrs.toml")
    reference = fe_frequencies(model, count=40).frequencies_hz
    for k, frequency in enumerate(reference):
        assert clamped_modes_below(model, 2 * np.pi * frequency * (1 - 1e-9)) <= k


def test_a_range_beyond_the_limit_is_refused_before_any_search():
    model = load_model(ROOT / "models" / "cantilever_tip_mass.toml")
    at_limit = 1.0
    while clamped_modes_below(model, 2 * np.pi * at_limit * 2) <= MAX_RANGE_MODES:
        at_limit *= 2
    check_range_request(model, at_limit)  # within the limit: no error
    with pytest.raises(ModelError, match=r"cantilever_tip_mass.toml: fmax = .* Hz: at least \d+ natural"):
        natural_frequencies(model, count=None, fmax=at_limit * 2)
    with pytest.raises(ModelError, match="must be a positive finite frequency"):
        natural_frequencies(model, count=None, fmax=np.inf)
