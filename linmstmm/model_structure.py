"""What a model is made of apart from its numbers, and what is kept by it.

A parameter study's models (:func:`linmstmm.parameters.with_values`) differ in
their numbers only: the same points, elements, ends and ports, releases and
boundary. :func:`structure_of` names that structure (a hashable tuple), and a
:class:`KeptByStructure` keeps what a computation derived from the structure
alone (a :class:`KeptByKey`, which keeps by any key, for what depends on more), so that the next model of the same structure takes it instead of
deriving it again. :func:`forget_structures` drops everything kept
(:func:`linmstmm.compiled_model.forget_compiled_models` calls it).
"""
from __future__ import annotations

import functools

import numpy as np

from linmstmm.model import Model

#: Model objects whose structure is kept (:func:`structure_of`), and what is kept by the structures of
#: as many (compiled systems, rigid parts, eliminations), least recently used dropped first.
MODELS_KEPT = 8


@functools.lru_cache(maxsize=MODELS_KEPT)
def structure_of(model: Model) -> tuple:
    """Everything about ``model`` that no change of its numbers changes.

    Parameters
    ----------
    model : Model
        The model (a Model hashes by identity: made once per model object).

    Returns
    -------
    tuple
        The point names in order; per element (rigid bodies, beams, springs, in
        order) its kind, name, ports or ends, and for a spring its released
        directions and which stiffnesses are infinite, for a beam whether it is
        rigid axially or in torsion; the boundary's points and fixed components.
        Equal for two models exactly where they differ in numbers only.
    """
    elements = []
    for element in model.elements:
        if element.kind == "rigid":
            elements.append(("rigid", element.name, element.ports))
        elif element.kind == "beam":
            elements.append(("beam", element.name, element.ends, bool(element.axial), bool(element.torsion)))
        else:
            released = element.released.tobytes()
            elements.append(("spring", element.name, element.ends, released, np.isinf(element.k).tobytes()))
    boundary = tuple((point, np.asarray(fixed, bool).tobytes()) for point, fixed in model.boundary.items())
    return tuple(model.points), tuple(elements), boundary


class KeptByKey:
    """What a computation derived, kept by a hashable key for the last ``kept`` keys
    (least recently used dropped first); :func:`forget_structures` forgets it.

    Parameters
    ----------
    kept : int
        Keys kept.
    """

    def __init__(self, kept: int):
        self.kept = kept
        self._kept: dict = {}
        _everything_kept.append(self)

    def __contains__(self, key) -> bool:
        return key in self._kept

    def __len__(self) -> int:
        return len(self._kept)

    def value(self, key, derive):
        """What ``derive()`` gives, derived on the first call with ``key`` kept.

        Parameters
        ----------
        key : hashable
            What the value depends on alone.
        derive : callable
            () -> the value.

        Returns
        -------
        object
            The kept value (the same object for every call with ``key``).
        """
        if key in self._kept:
            self._kept[key] = value = self._kept.pop(key)  # now the most recently used
            return value
        value = self._kept[key] = derive()
        if len(self._kept) > self.kept:
            del self._kept[next(iter(self._kept))]
        return value

    def clear(self) -> None:
        """Forget every key kept."""
        self._kept.clear()


class KeptByStructure(KeptByKey):
    """What one computation derived from a model's structure, kept for the last
    ``kept`` structures (least recently used dropped first).

    Parameters
    ----------
    kept : int
        Structures kept.
    """

    def get(self, model: Model, derive):
        """What ``derive(model)`` gives, derived on the first model of this structure.

        Parameters
        ----------
        model : Model
            The model.
        derive : callable
            model -> what depends on its structure alone (never on its numbers).

        Returns
        -------
        object
            The kept value (the same object for every model of the structure).
        """
        return self.value(structure_of(model), lambda: derive(model))


_everything_kept: list[KeptByKey] = []


def forget_structures() -> None:
    """Drop every structure named and everything kept by one."""
    structure_of.cache_clear()
    for kept in _everything_kept:
        kept.clear()
