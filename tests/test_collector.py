"""The cyclic collector paused while large structures are built (linmstmm.collector)."""
from __future__ import annotations

import gc

import pytest

from linmstmm.collector import collector_paused


def test_paused_inside_and_restored_after_even_on_error():
    assert gc.isenabled()
    with pytest.raises(ValueError):
        with collector_paused():
            assert not gc.isenabled()
            raise ValueError
    assert gc.isenabled()


def test_a_nested_pause_and_a_collector_the_caller_disabled_are_left_alone():
    with collector_paused():
        with collector_paused():
            pass
        assert not gc.isenabled()  # the inner pause did not restart it
    assert gc.isenabled()
    gc.disable()
    try:
        assert collector_paused()(gc.isenabled)() is False
        assert not gc.isenabled()
    finally:
        gc.enable()
