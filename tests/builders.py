"""The model builders for tests (they live in :mod:`linmstmm.builders`), and the bundled model files."""
import dataclasses
from pathlib import Path

import numpy as np

from linmstmm.builders import (STEEL, beam_axes, fixed, make_beam, make_rigid, make_spring,
                               single_beam_model, spring_chain, spring_mass_chain)

__all__ = ["STEEL", "beam_axes", "fixed", "make_beam", "make_rigid", "make_spring",
           "single_beam_model", "spring_mass_chain", "BUNDLED_MODELS", "cantilever_with_tip_dashpot",
           "cantilever_of_beams", "unequal_chain"]

from linmstmm.model import Model, ModelError, load_model  # noqa: E402


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


def cantilever_with_tip_dashpot(folder: Path):
    """models/cantilever_tip_mass.toml with a spring and dashpot from the tip body to
    the ground (k = 1000 N/m, 10 N m/rad; c = 30 N s/m along y, 60 along z: the
    double bending roots split), written into ``folder`` and loaded."""
    text = (Path(__file__).resolve().parents[1] / "models" / "cantilever_tip_mass.toml").read_text()
    text = text.replace('tip  = [2.0, 0.0, 0.0]', 'tip  = [2.0, 0.0, 0.0]\nmount = [2.0, 0.0, 0.0]\n'
                        'ground = [2.0, 0.0, 0.0]')
    text = text.replace('ports = ["tip"]', 'ports = ["tip", "mount"]')
    text = text.replace('[boundary]\nroot = "fixed"',
                        '[[spring]]\nname = "damper"\nends = ["mount", "ground"]\n'
                        'k = [1000.0, 1000.0, 1000.0, 10.0, 10.0, 10.0]\nc = [0.0, 30.0, 60.0, 0.0, 0.0, 0.0]\n\n'
                        '[boundary]\nroot = "fixed"\nground = "fixed"')
    path = folder / "tip_damper.toml"
    path.write_text(text)
    return load_model(path)


def cantilever_of_beams(n: int, length: float = 2.0) -> Model:
    """A steel cantilever along x, clamped at x = 0, cut into ``n`` equal beam elements
    (Iz = 3e-7 m^4, Iy = 2e-7 m^4: the two bending planes apart)."""
    points = {f"p{i}": np.array([length * i / n, 0.0, 0.0]) for i in range(n + 1)}
    beams = tuple(make_beam(f"b{i}", f"p{i}", f"p{i + 1}", points, Iz=3e-7) for i in range(n))
    return Model(f"cantilever of {n} beams", points, beams=beams, boundary={"p0": fixed()})


def unequal_chain(n: int) -> Model:
    """:func:`linmstmm.builders.spring_chain` of ``n`` bodies with masses drawn from 1 to 2 kg:
    no two cells alike, so the numpy carry takes it element by element."""
    chain = spring_chain(n)
    rng = np.random.default_rng(1)
    return dataclasses.replace(chain, rigids=tuple(dataclasses.replace(body, mass=float(1.0 + rng.random()))
                                                   for body in chain.rigids))
