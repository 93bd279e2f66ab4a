"""LAPACK routines for the compiled kernels, taken from scipy's own LAPACK.

numba's ``ExternalFunction`` calls a routine by symbol; the symbol is bound to
the address scipy's ``cython_lapack`` exports, under a name of our own, so
that machine code loaded from numba's cache finds it again in a new process.
Plain Python (no kernel is defined here): see the note on caching at the top
of :mod:`linmstmm._kernels`.
"""
from __future__ import annotations

import llvmlite.binding
from numba import types
from numba.extending import get_cython_function_address


def lapack_routine(name: str, arguments: int):
    """LAPACK routine ``name`` of scipy's ``cython_lapack``, callable from numba.

    Parameters
    ----------
    name : str
        The routine, e.g. "dgetrf".
    arguments : int
        How many arguments it takes; every one is passed as a pointer
        (``array.ctypes``), as Fortran does.

    Returns
    -------
    numba.types.ExternalFunction
        Returning nothing; errors come back in the routine's ``info`` argument.
    """
    symbol = f"linmstmm_{name}"
    llvmlite.binding.add_symbol(symbol, get_cython_function_address("scipy.linalg.cython_lapack", name))
    return types.ExternalFunction(symbol, types.void(*[types.voidptr] * arguments))
