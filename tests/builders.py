"""The model builders for tests (they live in :mod:`linmstmm.builders`), and the bundled model files."""
from pathlib import Path

from linmstmm.builders import (STEEL, beam_axes, fixed, make_beam, make_rigid, make_spring,
                               single_beam_model, spring_mass_chain)

__all__ = ["STEEL", "beam_axes", "fixed", "make_beam", "make_rigid", "make_spring",
           "single_beam_model", "spring_mass_chain", "BUNDLED_MODELS"]

from linmstmm.model import ModelError, load_model  # noqa: E402


def _is_model(path: Path) -> bool:
    """Whether ``path`` loads as a model (models/ also holds load files and bundles)."""
    try:
        load_model(path)
    except ModelError:
        return False
    return True


#: Every model file under models/, sorted.
BUNDLED_MODELS = [p for p in sorted((Path(__file__).resolve().parents[1] / "models").rglob("*.toml"))
                  if _is_model(p)]
