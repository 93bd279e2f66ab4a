"""∂f/∂p from the mode shapes (:mod:`linmstmm.sensitivity`) against central finite
differences of the solved frequencies (``natural_frequencies`` on models edited by
±h and ±h/2, h = 1e-4 relative, Richardson-extrapolated: truncation O(h⁴), rounding
of the roots about 1e-13 / 1e-4).

Compared as logarithmic sensitivities (p/f) ∂f/∂p, which are unit-free: the
beam keys on a cantilever whose tip mass has inertia and an offset mass
centre, and whose two bending planes differ (no repeated frequency); springs,
masses, inertias and mass centres on the launcher; a repeated frequency split
by a change on the spring-mass chain.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from linmstmm.model import ModelError, load_model
from linmstmm.modes import mode_shapes
from linmstmm.parameters import get_value, parse_key, with_values
from linmstmm.sensitivity import frequency_sensitivities
from linmstmm.solve import natural_frequencies
from linmstmm.sweep import ENGINE, sweep

MODELS = Path(__file__).resolve().parents[1] / "models"
STEP = 1e-4
#: Agreement of (p/f) ∂f/∂p with the central difference (both O(1) where a value matters).
AGREEMENT = 1e-6


def edited(model, values: dict):
    return with_values(model, {parse_key(model, k): v for k, v in values.items()})


def cantilever():
    return edited(load_model(MODELS / "cantilever_tip_mass.toml"),
                  {"beam.arm.Iz": 3e-7, "rigid.payload.inertia[0][0]": 0.01, "rigid.payload.inertia[1][1]": 0.02,
                   "rigid.payload.inertia[2][2]": 0.025, "rigid.payload.inertia[0][2]": 0.002,
                   "rigid.payload.com[2]": 0.1})


def central_difference(model, text, count, step=STEP):
    """(count,) ∂f/∂value by central differences at steps h and h/2 (h = step × |value|),
    Richardson-extrapolated: truncation O(h⁴)."""
    key = parse_key(model, text)
    value = get_value(model, key)

    def difference(h):
        up, down = (natural_frequencies(with_values(model, {key: value + s * h}), count=count).frequencies_hz
                    for s in (1, -1))
        return (up - down) / (2 * h)

    h = step * abs(value)
    return (4 * difference(h / 2) - difference(h)) / 3


def check(model, keys, count):
    modes = mode_shapes(model, count=count, rigid_body=False)
    assert np.ptp(modes.frequencies_hz) > 0 and np.all(np.diff(modes.frequencies_hz) > 1e-6 * modes.frequencies_hz[1:])
    derivatives = frequency_sensitivities(model, modes, keys)
    for text in keys:
        scale = abs(get_value(model, parse_key(model, text))) / modes.frequencies_hz[:count]
        expected = central_difference(model, text, count) * scale
        np.testing.assert_allclose(derivatives[text][:count] * scale, expected, rtol=0, atol=AGREEMENT, err_msg=text)
        assert np.abs(expected).max() > 100 * AGREEMENT, f"{text} does not move these modes: no test"


@pytest.mark.parametrize("key", ["beam.arm.E", "beam.arm.G", "beam.arm.rho", "beam.arm.A", "beam.arm.Iy",
                                 "beam.arm.Iz", "beam.arm.J", "beam.arm.Ip"])
def test_beam_section_values(key):
    check(cantilever(), [key], count=8)


def test_tip_body_mass_inertia_and_mass_centre():
    check(cantilever(), ["rigid.payload.mass", "rigid.payload.inertia[1][1]", "rigid.payload.inertia[0][2]",
                         "rigid.payload.com[0]", "rigid.payload.com[2]"], count=8)


def test_launcher_springs_and_bodies():
    check(load_model(MODELS / "mlrs" / "mlrs.toml"),
          ["spring.elevation.k[4]", "spring.tyre1.k[2]", "spring.bearing.k[5]", "rigid.cradle.mass",
           "rigid.cradle.inertia[1][1]", "rigid.cradle.inertia[0][2]", "rigid.cradle.com[2]"], count=5)


def test_a_repeated_frequency_splits_into_its_branches():
    """The chain's triple root at k2 = 1000 N/m: stiffening the middle spring along x moves
    only the x mode (the y and z modes keep their frequency), so the derivatives are
    (0, 0, d) with d the central difference of the sum of the three frequencies (steps of
    1 %, so that the solves need not tell nearly equal roots apart: truncation O(1e-8))."""
    model = load_model(MODELS / "spring_mass_chain.toml")
    modes = mode_shapes(model, count=3, rigid_body=False)
    derivative = frequency_sensitivities(model, modes, ["spring.k2.k[0]"])["spring.k2.k[0]"]
    slope = central_difference(model, "spring.k2.k[0]", 3, step=1e-2).sum()
    assert slope > 0
    np.testing.assert_allclose(derivative[:2], 0.0, atol=1e-12 * slope)
    np.testing.assert_allclose(derivative[2], slope, rtol=AGREEMENT)


def test_a_key_that_moves_the_geometry_is_refused():
    model = cantilever()
    modes = mode_shapes(model, count=2, rigid_body=False)
    with pytest.raises(ModelError, match=r"key 'points.tip\[0\]': moves the geometry"):
        frequency_sensitivities(model, modes, ["points.tip[0]"])


def test_sweep_reports_them_in_tracked_order():
    model = load_model(MODELS / "mlrs" / "mlrs.toml")
    result = sweep(model, [{"spring.elevation.k[4]": v} for v in (2e7, 3e7)], count=4, sensitivity=True)
    step = edited(model, {"spring.elevation.k[4]": 3e7})
    modes = mode_shapes(step, count=4, rigid_body=False, engine=ENGINE)  # the sweep's engine
    by_rank = frequency_sensitivities(step, modes, ["spring.elevation.k[4]"])
    tracked = result.sensitivities["spring.elevation.k[4]"][1]
    np.testing.assert_array_equal(tracked, by_rank["spring.elevation.k[4]"][:4][result.order[1]])


def hinged_chain(mass=3.0, length=0.8, kt=500.0):
    """Two rods in a row along x, pinned to the ground and to each other (rz released),
    a torsion spring kt (every direction but rz released) beside each pin."""
    from builders import fixed, make_rigid, make_spring

    from linmstmm.model import Model

    L, inf = length, np.inf
    points = {name: np.asarray(x, float) for name, x in
              dict(g=[0, 0, 0], a1=[0, 0, 0], b1=[L, 0, 0], a2=[L, 0, 0], b2=[2 * L, 0, 0]).items()}
    springs = []
    for i, (a, b) in enumerate((("g", "a1"), ("b1", "a2")), 1):
        springs.append(make_spring(f"pin{i}", a, b, [inf] * 5 + [0.0], release=["rz"]))
        springs.append(make_spring(f"torsion{i}", a, b, [0.0] * 5 + [kt], release=["x", "y", "z", "rx", "ry"]))
    rods = tuple(make_rigid(f"link{i}", [f"a{i}", f"b{i}"], mass, [(i - 0.5) * L, 0, 0],
                            [0.0, mass * L ** 2 / 12, mass * L ** 2 / 12]) for i in (1, 2))
    return Model("hinged chain", points, rigids=rods, springs=tuple(springs), boundary={"g": fixed()})


def test_a_joints_released_direction_has_no_sensitivity():
    """The stiffness of a released direction does not act (it is 0 by the contract);
    the torsion spring beside the pin does, and matches the central difference."""
    model = hinged_chain()
    modes = mode_shapes(model, count=2, rigid_body=False)
    derivatives = frequency_sensitivities(model, modes, ["spring.pin1.k[5]", "spring.torsion1.k[0]"])
    assert not derivatives["spring.pin1.k[5]"].any() and not derivatives["spring.torsion1.k[0]"].any()
    check(model, ["spring.torsion1.k[5]", "rigid.link2.mass"], count=2)
