"""Counts in messages, in the number that fits: "1 elastic mode", "2 elastic modes"."""
from __future__ import annotations


def counted(n: int, singular: str, plural: str | None = None) -> str:
    """``n`` and the noun (or noun and verb) in the number that fits it.

    Parameters
    ----------
    n : int
        How many.
    singular : str
        The words for one, e.g. "elastic natural frequency exists".
    plural : str, optional
        The words for any other number (default: ``singular`` + "s"), e.g.
        "elastic natural frequencies exist".

    Returns
    -------
    str
        E.g. "1 elastic natural frequency exists", "0 elastic natural frequencies exist".
    """
    return f"{n} {singular if n == 1 else (plural or singular + 's')}"
