"""Shared test set-up: every test starts with no compiled model kept from another."""
from __future__ import annotations

import pytest

from linmstmm.compiled_model import forget_compiled_models


@pytest.fixture(autouse=True)
def no_model_compiled_by_another_test():
    """Forget the models earlier tests compiled (:mod:`linmstmm.compiled_model`): a test
    that patches a compilation step (a counter left out, a threshold moved) then sees
    its patch act on a model object another test solved first, and no test depends on
    the order tests run in."""
    forget_compiled_models()
    yield
