"""Roots to any number of digits: refinement of float64 roots in mpmath.

The float64 search (:mod:`linmstmm.roots`) finds every root and its
multiplicity; this module refines them with det Ū_all evaluated in mpmath
(the same element and deduction code on object arrays), at the requested
number of digits plus guard digits that cover the growth of the beam
functions (e^{βL} along a path). A simple root is refined by the secant
method; a root of multiplicity m > 1 by modified Newton (mpmath's
``mnewton``), which converges quadratically on multiple zeros.
"""
from __future__ import annotations

import math

import mpmath
import numpy as np

from linmstmm.elements.beam import bending_wavenumber

#: Guard digits on top of the growth estimate.
GUARD_DIGITS = 12


def growth_digits(model, omega: float) -> int:
    """Decimal digits the beam functions grow by at ``omega`` (rad/s): Σ βL / ln 10."""
    total = sum(bending_wavenumber(beam, omega) * beam.length for beam in model.beams)
    return int(math.ceil(total / math.log(10)))


def mp_determinant(deduction, omega) -> mpmath.mpf:
    """det Ū_all(ω) in mpmath at the working precision (omega an mpf)."""
    ubar = deduction.matrix(np.array([omega], dtype=object))[0]
    return mpmath.det(mpmath.matrix(ubar.tolist()))


def refine_roots(deduction, model, omegas, digits: int) -> list:
    """The roots ``omegas`` (rad/s, ascending, repeated per multiplicity) to ``digits`` digits.

    Returns mpf values, one per entry of ``omegas``.
    """
    refined = []
    i = 0
    while i < len(omegas):
        m = 1
        while i + m < len(omegas) and omegas[i + m] == omegas[i]:
            m += 1
        dps = digits + GUARD_DIGITS + growth_digits(model, omegas[i])
        with mpmath.workdps(dps):
            start = mpmath.mpf(omegas[i])
            root = mpmath.findroot(lambda w: mp_determinant(deduction, w), start,
                                   solver="secant" if m == 1 else "mnewton",
                                   tol=(start * mpmath.mpf(10) ** -(digits + 2)) ** 2, verify=False)
            refined += [+root] * m
        i += m
    return refined
