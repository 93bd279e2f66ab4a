"""linmstmm: natural frequencies, mode shapes and modal response of
multi-rigid-flexible-body systems by the linear transfer matrix method for
multibody systems (MSTMM, the "Rui method").

Quick start::

    import linmstmm as lm

    model = lm.load_model("models/cantilever_tip_mass.toml")
    lm.natural_frequencies(model, count=3).frequencies_hz   # Hz, (3,)

Public names (each documented where it is defined):

* models: :func:`load_model`, :class:`Model`, :class:`ModelError`, and the
  builders of :mod:`linmstmm.builders` (models in Python, without a file);
* frequencies: :func:`natural_frequencies` -> :class:`FrequencyResult`
  (transfer matrix method), :func:`fe_frequencies` -> :class:`FEResult`
  (the independent finite-element route);
* modes: :func:`mode_shapes` -> :class:`ModalResult`, :func:`mac_matrix`;
* response: :func:`load_loads` -> :class:`LoadCase`, :func:`respond` and
  :func:`modal_response` -> :class:`ResponseResult` (time histories),
  :func:`frf` -> :class:`FRFResult` (receptance), :class:`PointLoad`;
* dashpots: :func:`direct_frf` -> :class:`FRFResult` (the direct solve,
  spring dashpots acting), :func:`damped_frequencies` -> :class:`DampedResult`
  (complex roots of det Ū_all);
* parameter studies: the modules :mod:`linmstmm.parameters` (keys naming
  model values), :mod:`linmstmm.sweep` (sweeps with modes tracked by MAC)
  and :mod:`linmstmm.sensitivity` (∂f/∂p from the mode shapes);
* results: :class:`Result`, the base of every result class above
  (``to_dict``/``from_dict``, ``save``/``load`` as JSON, ``plot()`` returning
  a matplotlib Figure).

The names are imported on first use, so ``import linmstmm`` stays light
(in particular, matplotlib is only imported by the plotting functions).
Guides: ``docs/api.md``, ``docs/model-format.md``, ``docs/cli.md``,
``docs/method.md``.
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: Public name -> the module that defines it.
_SOURCES = {
    "load_model": "linmstmm.model",
    "Model": "linmstmm.model",
    "ModelError": "linmstmm.model",
    "natural_frequencies": "linmstmm.solve",
    "FrequencyResult": "linmstmm.solve",
    "mode_shapes": "linmstmm.modes",
    "ModalResult": "linmstmm.modes",
    "mac_matrix": "linmstmm.modes",
    "fe_frequencies": "linmstmm.fe",
    "FEResult": "linmstmm.fe",
    "load_loads": "linmstmm.loads",
    "respond": "linmstmm.response",
    "modal_response": "linmstmm.response",
    "frf": "linmstmm.response",
    "direct_frf": "linmstmm.forced",
    "damped_frequencies": "linmstmm.damped",
    "DampedResult": "linmstmm.damped",
    "LoadCase": "linmstmm.loads",
    "PointLoad": "linmstmm.loads",
    "ResponseResult": "linmstmm.response",
    "FRFResult": "linmstmm.response",
    "builders": "linmstmm.builders",
    "parameters": "linmstmm.parameters",
    "sweep": "linmstmm.sweep",
    "sensitivity": "linmstmm.sensitivity",
    "Result": "linmstmm.results",
}

#: Public names that are modules (the rest are defined in their module).
_MODULES = {"builders", "parameters", "sweep", "sensitivity"}

__all__ = list(_SOURCES)


def __getattr__(name: str):
    """Import a public name from its module on first use (PEP 562)."""
    if name not in _SOURCES:
        raise AttributeError(f"module 'linmstmm' has no attribute {name!r}")
    module = importlib.import_module(_SOURCES[name])
    value = module if name in _MODULES else getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the public ones included before their first use."""
    return sorted(set(globals()) | set(__all__))
