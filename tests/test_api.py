"""The public Python API: ``import linmstmm as lm`` and the names in ``lm.__all__``."""
from __future__ import annotations

import importlib
import pydoc
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import linmstmm as lm

REPO = Path(__file__).resolve().parents[1]


def test_import_is_light():
    """``import linmstmm`` loads neither matplotlib nor the solver (names load on first use)."""
    code = ("import sys, linmstmm; "
            "print(sorted(m for m in ('matplotlib', 'scipy', 'linmstmm.solve') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True,
                         check=True, env={"PYTHONPATH": str(REPO)})
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("name", lm.__all__)
def test_public_names_are_their_modules_objects(name):
    source = importlib.import_module(lm._SOURCES[name])
    expected = source if name in lm._MODULES else getattr(source, name)
    assert getattr(lm, name) is expected


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'natural_frequency'"):
        lm.natural_frequency  # noqa: B018 (a misspelling must not pass silently)


def test_help_lists_the_public_names():
    text = pydoc.render_doc(lm, renderer=pydoc.plaintext)
    for name in lm.__all__:
        assert name in text, name


def test_quick_start_agrees_with_the_fe_route():
    """The README's one-liner; its frequencies against the finite-element route on the same file."""
    model = lm.load_model(REPO / "models" / "cantilever_tip_mass.toml")
    ours = lm.natural_frequencies(model, count=3).frequencies_hz
    fe = lm.fe_frequencies(model, count=3)
    assert ours.shape == (3,)
    np.testing.assert_allclose(ours, fe.frequencies_hz, rtol=max(1e-8, 10 * fe.error_estimate.max()))


def test_builders_make_the_model_of_the_file():
    """A model built in Python has the frequencies of the same model read from TOML."""
    from linmstmm.builders import spring_mass_chain

    built = lm.natural_frequencies(spring_mass_chain(), count=6).frequencies_hz
    read = lm.natural_frequencies(lm.load_model(REPO / "models" / "spring_mass_chain.toml"),
                                  count=6).frequencies_hz
    np.testing.assert_allclose(built, read, rtol=1e-12)
