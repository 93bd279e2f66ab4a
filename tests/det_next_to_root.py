"""det Ū_all next to a root against mpmath's: the referee of the precision tests."""
from __future__ import annotations

import mpmath
import numpy as np

from linmstmm.precision import mp_determinant, working_digits


def det_errors_next_to(model, deduction, determinant, root: float, offset: float) -> np.ndarray:
    """(2,) relative errors of ``determinant``'s det Ū_all at ``root`` (rad/s) × (1 ∓ ``offset``)
    against mpmath's (20 digits more than float64 needs there), whose signs it has."""
    points = root * (1 + np.array([-offset, offset]))
    sign, log_abs = np.concatenate([np.stack(determinant.log_det(np.array([x]))) for x in points], axis=1)
    with mpmath.workdps(working_digits(model, root, 20)):
        exact = [mp_determinant(deduction, mpmath.mpf(x)) for x in points]
    assert [np.real(s) for s in sign] == [mpmath.sign(value) for value in exact]
    return np.abs(np.expm1(log_abs - np.array([float(mpmath.log(abs(value))) for value in exact])))
