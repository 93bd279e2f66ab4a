"""The one-line notice of a first run's compilation (linmstmm._compile_notice): said once
where numba compiles a kernel of the package, never where it loads one from its cache."""
from __future__ import annotations

import os
import subprocess
import sys
from types import SimpleNamespace

from linmstmm._compile_notice import NOTICE, _FirstCompilation

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

#: A new process calling one small kernel of the package.
CALL_ONE_KERNEL = ("import numpy as np\n"
                   "from linmstmm._assembly_kernels import _kept_at\n"
                   "assert list(_kept_at(np.array([0, 2]), 3)) == [0, -1, 1]\n")


def compilation_of(module: str) -> SimpleNamespace:
    """A ``numba:compile`` event as numba makes it, for a function of ``module``."""
    function = SimpleNamespace(__module__=module)
    return SimpleNamespace(data=dict(dispatcher=SimpleNamespace(py_func=function), args=(), return_type=None))


def test_said_once_and_only_for_the_package_s_kernels(capsys):
    listener = _FirstCompilation()
    listener.on_start(compilation_of("someone_else"))
    assert capsys.readouterr().err == ""
    listener.on_start(compilation_of("linmstmm._kernels"))
    listener.on_start(compilation_of("linmstmm._stiffness_kernels"))
    assert capsys.readouterr().err == NOTICE + "\n"


def test_a_new_process_says_it_when_it_compiles_and_not_when_the_cache_holds_the_kernel(tmp_path):
    environment = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), PYTHONPATH=REPO)

    def run():
        done = subprocess.run([sys.executable, "-c", CALL_ONE_KERNEL], env=environment, cwd=REPO,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        return done.stderr

    assert run() == NOTICE + "\n"  # an empty cache: compiled here
    assert run() == ""  # loaded from the cache the first run wrote


def test_every_kernel_module_installs_the_notice():
    """A module of compiled kernels that forgot the call would compile silently when it
    is the first loaded (the walk's kernel is, on a model's first compilation)."""
    package = os.path.join(REPO, "linmstmm")
    kernel_modules = [name for name in sorted(os.listdir(package)) if name.endswith(".py")
                      and "\n@njit" in open(os.path.join(package, name), encoding="utf-8").read()]
    assert len(kernel_modules) >= 6
    for name in kernel_modules:
        source = open(os.path.join(package, name), encoding="utf-8").read()
        assert "\nannounce_compiles()" in source, name
