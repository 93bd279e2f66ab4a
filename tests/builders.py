"""The model builders for tests: they live in :mod:`linmstmm.builders`."""
from linmstmm.builders import (STEEL, beam_axes, fixed, make_beam, make_rigid, make_spring,
                               single_beam_model, spring_mass_chain)

__all__ = ["STEEL", "beam_axes", "fixed", "make_beam", "make_rigid", "make_spring",
           "single_beam_model", "spring_mass_chain"]
