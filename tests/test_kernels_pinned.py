"""The compiled evaluation of det Ū_all, pinned to the bit.

The kernels replay the program with their own loops, scratch arrays and
summation orders; a change that only makes them cheaper must leave every
number they return unchanged. The pinned values below (sign or phase,
log|det Ū_all|, the log-scale, and a digest of the bits of the orthonormalised
and the plain Ū_all) were written by the kernel before its scratch arrays were
allocated once per evaluation, and written again when the determinant came to
be taken over the blocks of its lone columns and the rest (an LU of fewer
rows rounds otherwise: log|det| moved by 1 to 86 units in its last place, and
by 3,860 (2.2e-10) on launcher2 at 410 rad/s; Ū_all itself did not move); the numpy carry (:meth:`Deduction.log_det`)
agrees with them to 1e-12 relative in log|det|, which this test checks too.

The bits depend on the machine's BLAS and LAPACK (numba calls them for a beam
piece's rotation and for the LU): on another build the pins may differ while
the agreement with the numpy carry holds. The bits are compared only on the build
they were written on (:data:`PINNED_BUILD`: numpy, scipy and numba versions and the
BLAS libraries' versions and kernels); elsewhere that test is skipped with the
reason, and the agreement with the numpy carry is still checked.
``python3 tests/test_kernels_pinned.py`` prints the values of the kernels as they
stand, in the form pinned here, and the build they belong to.
"""
from __future__ import annotations

import hashlib

import numba
import numpy as np
import pytest
import scipy
from threadpoolctl import threadpool_info

from linmstmm.deduction import Deduction
from linmstmm.determinant import CompiledDeterminant
from linmstmm.model import load_model
from linmstmm.nullspace import release_indeterminate
from linmstmm.topology import build_topology
from random_models import random_model
from test_joints import four_bar

#: name: (model builder, frequencies rad/s, real and complex; from below the first root to above the tenth)
CASES = {
    "launcher2": (lambda: load_model("models/launcher2/launcher2.toml"), [7.3, 410.0, 3900.0, 2100.0 * (1 + 0.01j)]),
    "mlrs": (lambda: load_model("models/mlrs/mlrs.toml"), [3.1, 240.0, 1900.0, 950.0 * (1 - 0.003j)]),
    "cantilever": (lambda: load_model("models/cantilever_tip_mass.toml"), [27.0, 1900.0, 240.0 * (1 + 0.01j)]),
    "tree": (lambda: random_model("tree", 1), [3.1, 240.0, 27.0 * (1 + 0.01j)]),
    "floating_loops": (lambda: random_model("floating_loops", 2), [0.37, 240.0, 1900.0 * (1 - 0.003j)]),
    "ring": (lambda: random_model("ring", 3), [27.0, 1900.0, 240.0 * (1 + 0.01j)]),
    "four_bar": (four_bar, [3.1, 240.0, 27.0 * (1 - 0.003j)]),
}


def this_build() -> tuple:
    """(numpy, scipy, numba versions, each BLAS library's (api, version, kernels)) of this process."""
    import scipy.linalg  # noqa: F401 - scipy's BLAS loaded, so that it is listed

    libraries = sorted((info.get("internal_api"), info.get("version"), info.get("architecture"))
                       for info in threadpool_info() if info.get("user_api") == "blas")
    return (np.__version__, scipy.__version__, numba.__version__, tuple(map(tuple, libraries)))


def _digest(array: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest()[:16]


def _hex(values) -> list[str]:
    """Each value exactly: float.hex of the real part, and of the imaginary part if complex."""
    return [float(v.real).hex() + (" " + float(v.imag).hex() if np.iscomplexobj(values) else "") for v in values]


def determinants(name: str) -> tuple[Deduction, CompiledDeterminant]:
    deduction = Deduction(build_topology(CASES[name][0]()))
    release_indeterminate(deduction)
    return deduction, CompiledDeterminant(deduction)


def fingerprint(compiled: CompiledDeterminant, omega: complex) -> dict:
    """What the kernels return at ``omega``: alone (sign, log|det|, log-scale), in a stack
    of two sharing their decisions (Newton's pencil), and the plain Ū_all."""
    omega = np.array([omega])
    matrices, sign, log_abs, log_scale = compiled._evaluate(omega, 1, True)
    pair, pair_scale = compiled.matrix(np.concatenate([omega, omega * (1 + 1e-7)]))
    return {"sign": _hex(sign)[0], "log_abs": _hex(log_abs)[0], "log_scale": _hex(log_scale)[0],
            "matrix": _digest(matrices), "pair": _digest(pair), "pair_scale": _hex(pair_scale),
            "plain": _digest(compiled.plain_matrix(omega))}


@pytest.mark.parametrize("name", CASES)
def test_kernels_return_the_pinned_bits(name):
    if this_build() != PINNED_BUILD:
        pytest.skip(f"the bits were pinned on {PINNED_BUILD}, this is {this_build()}")
    deduction, compiled = determinants(name)
    for omega, pinned in zip(CASES[name][1], PINNED[name]):
        assert fingerprint(compiled, omega) == pinned, omega


@pytest.mark.parametrize("name", CASES)
def test_pinned_values_are_the_numpy_carrys(name):
    """The pins are the determinant the numpy carry computes: log|det| to 1e-12
    relative, the sign or phase to 1e-9."""
    deduction, _ = determinants(name)
    for omega, pinned in zip(CASES[name][1], PINNED[name]):
        sign, log_abs = deduction.log_det(np.array([omega]))
        pinned_log_abs = float.fromhex(pinned["log_abs"])
        assert abs(pinned_log_abs - log_abs[0]) <= 1e-12 * max(1.0, abs(log_abs[0])), omega
        parts = [float.fromhex(part) for part in pinned["sign"].split()]
        pinned_sign = complex(*parts) if len(parts) == 2 else parts[0]
        assert abs(pinned_sign - sign[0]) <= 1e-9, omega


#: Written by the kernel before its scratch arrays were allocated once per evaluation.
PINNED = {'launcher2': [{'sign': '-0x1.0000000000000p+0',
                'log_abs': '-0x1.cfc94ea70090dp+8',
                'log_scale': '-0x1.7118ccbcb56ebp+6',
                'matrix': 'beaf883b7c300ac9',
                'pair': 'bd24e81f741cbf63',
                'pair_scale': ['-0x1.7118ccbcb56ebp+6', '-0x1.7118cd5dcd5a0p+6'],
                'plain': '2e770c8aaa63e1d9'},
               {'sign': '0x1.0000000000000p+0',
                'log_abs': '-0x1.7cd9be8006fdfp+8',
                'log_scale': '-0x1.41824591c7497p+9',
                'matrix': '0ea24555852e13c6',
                'pair': 'e49ee6928e09b00b',
                'pair_scale': ['-0x1.41824591c7497p+9', '-0x1.418245e921563p+9'],
                'plain': 'f28d55344cc5d8fe'},
               {'sign': '-0x1.0000000000000p+0',
                'log_abs': '-0x1.316f450a3f050p+7',
                'log_scale': '-0x1.dd1cd052fc06ap+9',
                'matrix': '27ecc38e3d420189',
                'pair': '55219a4f7452b26d',
                'pair_scale': ['-0x1.dd1cd052fc06ap+9', '-0x1.dd1cd097fe705p+9'],
                'plain': 'dff347694eb3f253'},
               {'sign': '-0x1.8b416e875ed3bp-1 -0x1.4572ee1deef85p-1',
                'log_abs': '-0x1.c7a6af55f89e4p+7',
                'log_scale': '-0x1.b04014722588fp+9',
                'matrix': 'dbf35623d9520877',
                'pair': '9d2afef4ab6d5b9c',
                'pair_scale': ['-0x1.b04014722588fp+9', '-0x1.b04014c103128p+9'],
                'plain': '97afa25c0a52c93d'}],
 'mlrs': [{'sign': '0x1.0000000000000p+0',
           'log_abs': '-0x1.a57e22d84e638p+8',
           'log_scale': '-0x1.bf22c650f8d5bp+6',
           'matrix': '879e7c13592f57cc',
           'pair': '454a3d59ebb97914',
           'pair_scale': ['-0x1.bf22c650f8d5bp+6', '-0x1.bf22c651056b1p+6'],
           'plain': 'd86bac8bb51b856b'},
          {'sign': '-0x1.0000000000000p+0',
           'log_abs': '-0x1.9c964c82b2deep+8',
           'log_scale': '-0x1.0c41cef848a5ap+8',
           'matrix': '827431e47fbe4749',
           'pair': '054df94c2a68f670',
           'pair_scale': ['-0x1.0c41cef848a5ap+8', '-0x1.0c41cf4fa612dp+8'],
           'plain': '1c15ba4f00c847ac'},
          {'sign': '-0x1.0000000000000p+0',
           'log_abs': '-0x1.34fe86ecdeb34p+7',
           'log_scale': '-0x1.175e74d0f1888p+9',
           'matrix': 'c62ddf2e4123f149',
           'pair': '3e168a99138a96b1',
           'pair_scale': ['-0x1.175e74d0f1888p+9', '-0x1.175e754fda2c9p+9'],
           'plain': '85210beed06a22ae'},
          {'sign': '-0x1.e02265125d2c3p-1 0x1.639cb64477015p-2',
           'log_abs': '-0x1.ec3b7f956085dp+7',
           'log_scale': '-0x1.4912cf6e30404p+8',
           'matrix': '9a26dba2ae0ca2e1',
           'pair': '54b853bfe141dc1c',
           'pair_scale': ['-0x1.4912cf6e30404p+8', '-0x1.4912cff60d094p+8'],
           'plain': '85e6df0e2fc0420f'}],
 'cantilever': [{'sign': '-0x1.0000000000000p+0',
                 'log_abs': '-0x1.0dff332f32f88p+0',
                 'log_scale': '-0x1.20c869865aed4p+1',
                 'matrix': 'de6defa67ec610a2',
                 'pair': 'e8a8e9f750f81e03',
                 'pair_scale': ['-0x1.20c869865aed4p+1', '-0x1.20c869865aed5p+1'],
                 'plain': '73ca16bf22cfe802'},
                {'sign': '-0x1.0000000000000p+0',
                 'log_abs': '0x1.f4d59ebf063c4p+3',
                 'log_scale': '-0x1.fdf13a4e4ca0ep+4',
                 'matrix': 'ac14b56ab76df7b1',
                 'pair': 'b9107469ad0b1c62',
                 'pair_scale': ['-0x1.fdf13a4e4ca0ep+4', '-0x1.fdf13c14c1611p+4'],
                 'plain': '5c51b61bb9706b47'},
                {'sign': '-0x1.fff28a3d65389p-1 0x1.d597bcdd36c52p-7',
                 'log_abs': '0x1.40d696339e346p+2',
                 'log_scale': '-0x1.20c869865aed5p+1',
                 'matrix': 'f1026ced607623dc',
                 'pair': 'f1df4593bf3c4e91',
                 'pair_scale': ['-0x1.20c869865aed5p+1', '-0x1.20c869865aed5p+1'],
                 'plain': 'ebac2312345e2816'}],
 'tree': [{'sign': '-0x1.0000000000000p+0',
           'log_abs': '-0x1.49371034834d8p+6',
           'log_scale': '-0x1.237877e95b5c7p+4',
           'matrix': '5133102b70e92be5',
           'pair': '19e098ed930b34e1',
           'pair_scale': ['-0x1.237877e95b5c7p+4', '-0x1.237878c012be2p+4'],
           'plain': '3578646cf7cadfe0'},
          {'sign': '0x1.0000000000000p+0',
           'log_abs': '-0x1.3d40590b3af49p+6',
           'log_scale': '-0x1.168dd2b7a3700p+6',
           'matrix': '9da95583ea99c597',
           'pair': '029962baff2c7c97',
           'pair_scale': ['-0x1.168dd2b7a3700p+6', '-0x1.168dd2fd88941p+6'],
           'plain': '1231ad04347af8a3'},
          {'sign': '-0x1.ff94373608bf8p-1 0x1.4c273ac0aba7cp-5',
           'log_abs': '-0x1.4e73d017d4430p+6',
           'log_scale': '-0x1.1c1262988e3ecp+5',
           'matrix': '3d9dd2536d3577a4',
           'pair': '63dded1d68e1fc73',
           'pair_scale': ['-0x1.1c1262988e3ecp+5', '-0x1.1c1263015f043p+5'],
           'plain': '8d30ac51619dbbd7'}],
 'floating_loops': [{'sign': '-0x1.0000000000000p+0',
                     'log_abs': '-0x1.a3fc350ffa8c0p+6',
                     'log_scale': '0x0.0p+0',
                     'matrix': 'd28bd5c88fc5fd36',
                     'pair': 'a8ceb9c663232ba8',
                     'pair_scale': ['0x0.0p+0', '0x0.0p+0'],
                     'plain': 'd28bd5c88fc5fd36'},
                    {'sign': '-0x1.0000000000000p+0',
                     'log_abs': '-0x1.c5761c38f12b0p+4',
                     'log_scale': '-0x1.22fdb5ec768e1p+7',
                     'matrix': 'f6c9e8b7dd8e3753',
                     'pair': '279c6c086cef0274',
                     'pair_scale': ['-0x1.22fdb5ec768e1p+7', '-0x1.22fdb626e8bcap+7'],
                     'plain': 'd78de06d9aa27879'},
                    {'sign': '0x1.fe7b351227eb8p-1 -0x1.3b404deb1a3cap-4',
                     'log_abs': '-0x1.e0d646e6aa600p-2',
                     'log_scale': '-0x1.d53940b590a84p+7',
                     'matrix': '73bd8299ad458848',
                     'pair': '864f5ed6e3971f49',
                     'pair_scale': ['-0x1.d53940b590a84p+7', '-0x1.d53941861910bp+7'],
                     'plain': '6155fe878c7971ab'}],
 'ring': [{'sign': '0x1.0000000000000p+0',
           'log_abs': '0x1.28e5f08b4b2f4p+4',
           'log_scale': '-0x1.ada3c1b653f0cp+6',
           'matrix': 'f95bd847fb962b93',
           'pair': 'd5e53cda13243836',
           'pair_scale': ['-0x1.ada3c1b653f0cp+6', '-0x1.ada3c28149ce8p+6'],
           'plain': '6a03e487511f314f'},
          {'sign': '-0x1.0000000000000p+0',
           'log_abs': '0x1.8876b2d7e912cp+6',
           'log_scale': '-0x1.5f38e93787619p+8',
           'matrix': '11cfc82bb9ca7356',
           'pair': '91c182b393c930dd',
           'pair_scale': ['-0x1.5f38e93787619p+8', '-0x1.5f38e9bbf6bffp+8'],
           'plain': '17bd41457481a2fc'},
          {'sign': '-0x1.ea8751aa96fa9p-1 -0x1.256ecc3225b20p-2',
           'log_abs': '0x1.69d091242d818p+5',
           'log_scale': '-0x1.be934a735be84p+7',
           'matrix': '2ed0148294178136',
           'pair': '2332f9c936a64d62',
           'pair_scale': ['-0x1.be934a735be84p+7', '-0x1.be934b17aa3e5p+7'],
           'plain': 'e1ece5834a2b9bfb'}],
 'four_bar': [{'sign': '0x1.0000000000000p+0',
               'log_abs': '-0x1.d843c900f82aap+4',
               'log_scale': '0x0.0p+0',
               'matrix': '2773594282f5ef74',
               'pair': 'fab0c3151d988cef',
               'pair_scale': ['0x0.0p+0', '0x0.0p+0'],
               'plain': '2773594282f5ef74'},
              {'sign': '0x1.0000000000000p+0',
               'log_abs': '-0x1.5973f03c2ca1ep+4',
               'log_scale': '-0x1.f16e4d1d47635p+5',
               'matrix': '157a52c9b55e106a',
               'pair': '91e4be21a531ba7e',
               'pair_scale': ['-0x1.f16e4d1d47635p+5', '-0x1.f16e4db9570f6p+5'],
               'plain': '7fa0384a4b2609c3'},
              {'sign': '0x1.fffdadcf377bfp-1 -0x1.8603c0e0a0152p-8',
               'log_abs': '-0x1.9321824d7e3fep+4',
               'log_scale': '-0x1.1faed3495d3e9p+5',
               'matrix': '9978cab401dcb81b',
               'pair': 'a59666eeef9e7a46',
               'pair_scale': ['-0x1.1faed3495d3e9p+5', '-0x1.1faed3ea7edecp+5'],
               'plain': 'c1291cd3119f9d97'}]}

#: The build the bits above were written on (:func:`this_build`).
PINNED_BUILD = ('2.4.6', '1.17.1', '0.68.1', (('openblas', '0.3.30', 'SkylakeX'), ('openblas', '0.3.31.188.0', 'SkylakeX')))


if __name__ == "__main__":
    import pprint

    print("PINNED_BUILD =", this_build())
    pprint.pprint({name: [fingerprint(determinants(name)[1], omega) for omega in CASES[name][1]] for name in CASES},
                  width=120, sort_dicts=False)
