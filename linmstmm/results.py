"""One shape for every result: a dictionary, a JSON file and a figure.

:class:`Result` is the base of the package's result classes
(:class:`~linmstmm.solve.FrequencyResult`, :class:`~linmstmm.modes.ModalResult`,
:class:`~linmstmm.fe.FEResult`, :class:`~linmstmm.damped.DampedResult`,
:class:`~linmstmm.response.ResponseResult`, :class:`~linmstmm.response.FRFResult`,
:class:`~linmstmm.sweep.SweepResult`, :class:`~linmstmm.studies.ScanResult`). Each subclass gives

* ``to_dict()``: its JSON object (what the command line prints);
* ``_restoring_dict()``: what ``to_dict`` leaves out that rebuilding needs
  (mode shapes, the augmented eigenvectors, modal coordinates, a scan's grid;
  none for most);
* ``_from_data(data)``: the object rebuilt from the two together;
* ``plot(...)``: its figure.

The base turns these into :meth:`Result.from_dict`, :meth:`Result.save` and
:meth:`Result.load`. A saved file is a JSON object ``{"kind", "version",
"result"}``: the subclass's ``kind`` (e.g. ``"freqs"``), the package version
that wrote it and ``to_dict()`` with the restoring keys. Arrays are lists
(nested by their shape), complex arrays ``{"real": [...], "imag": [...]}``;
numbers are written by ``repr``, so float64 values come back bit for bit.

The helpers :func:`encode_array` and :func:`decode_array` are the array
encoding the subclasses share.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import ClassVar

import numpy as np

from linmstmm.model import ModelError

#: The keys of a saved file.
FILE_KEYS = ("kind", "version", "result")


class Result:
    """Base of the result classes: ``to_dict``/``from_dict``, ``save``/``load`` and ``plot``.

    Attributes
    ----------
    kind : str
        The name a saved file gives this class of result (class attribute).
    """

    kind: ClassVar[str] = ""
    #: kind -> class, for every subclass imported so far (to name the right one in an error).
    _kinds: ClassVar[dict] = {}

    def __init_subclass__(cls, **options):
        super().__init_subclass__(**options)
        if cls.kind:
            Result._kinds[cls.kind] = cls

    def to_dict(self) -> dict:
        """The result as plain JSON types (the command line's object; each subclass's own).

        Returns
        -------
        dict
            Keys and units as the subclass documents them.
        """
        raise NotImplementedError(f"{type(self).__name__} does not define to_dict")

    def _restoring_dict(self) -> dict:
        """What :meth:`from_dict` needs besides :meth:`to_dict` (nothing unless a subclass says)."""
        return {}

    @classmethod
    def _from_data(cls, data: dict) -> Result:
        """The result rebuilt from ``to_dict()`` merged with ``_restoring_dict()`` (each subclass's own)."""
        raise NotImplementedError(f"{cls.__name__} does not define _from_data")

    def to_record(self) -> dict:
        """Everything :meth:`from_dict` needs: :meth:`to_dict` and the keys it leaves out.

        Returns
        -------
        dict
            Plain JSON types; ``type(self).from_dict(self.to_record())`` rebuilds the result.
        """
        return {**self.to_dict(), **self._restoring_dict()}

    @classmethod
    def from_dict(cls, data: dict) -> Result:
        """Rebuild a result from :meth:`to_record` (or :meth:`to_dict`, where that holds everything).

        Parameters
        ----------
        data : dict
            The dictionary; arrays as (nested) lists, complex ones as
            ``{"real": ..., "imag": ...}``.

        Returns
        -------
        Result
            An object of this class equal to the one ``data`` came from: the
            same attributes, arrays of the same dtype, shape and values.

        Raises
        ------
        ModelError
            A key the class needs is missing (named as the key).
        """
        return cls._rebuilt(data, f"{cls.__name__}.from_dict")

    @classmethod
    def _rebuilt(cls, data: dict, source: str) -> Result:
        """``_from_data(data)``, a missing key reported as a :class:`ModelError` of ``source``."""
        try:
            return cls._from_data(data)
        except KeyError as missing:
            raise ModelError(source, f"missing: {cls.__name__} needs it (to_dict leaves it out; "
                             "to_record and save keep it)", element=f"{cls.kind} result",
                             key=missing.args[0]) from None

    def save(self, path) -> None:
        """Write the result to a JSON file that :meth:`load` reads back.

        Parameters
        ----------
        path : str or os.PathLike
            The file to write (replaced if it exists).
        """
        from linmstmm import __version__

        record = {"kind": self.kind, "version": __version__, "result": self.to_record()}
        Path(path).write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")

    @classmethod
    def load(cls, path) -> Result:
        """Read a result written by :meth:`save` of this class (``Result.load``: of any class).

        Parameters
        ----------
        path : str or os.PathLike
            A JSON file written by ``save``.

        Returns
        -------
        Result
            The result, equal to the one saved.

        Raises
        ------
        ModelError
            The file is not JSON, not a saved result, or a result of another
            kind (the message names the class that reads it).
        """
        try:
            record = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
            raise ModelError(path, f"cannot be read as a saved result: {error}") from None
        if not isinstance(record, dict) or not set(FILE_KEYS) <= set(record):
            raise ModelError(path, f"is not a saved result: a JSON object with keys {', '.join(FILE_KEYS)} expected")
        if cls is Result:  # any kind: the class that wrote it reads it
            _import_result_classes()
            if record["kind"] not in Result._kinds:
                raise ModelError(path, f"is a result of unknown kind {record['kind']!r}", key="kind")
            return Result._kinds[record["kind"]]._rebuilt(record["result"], str(path))
        if record["kind"] != cls.kind:
            other = Result._kinds.get(record["kind"])
            hint = f"; {other.__name__}.load reads it" if other else ""
            raise ModelError(path, f"is a {record['kind']!r} result, not {cls.kind!r}{hint}", key="kind")
        return cls._rebuilt(record["result"], str(path))

    def plot(self, **options):
        """The result's figure (each subclass says what it draws and which options it takes).

        Parameters
        ----------
        **options
            The subclass's drawing options.

        Returns
        -------
        matplotlib.figure.Figure
            Drawn on matplotlib's Agg canvas (matplotlib is imported only here), not saved.
        """
        raise NotImplementedError(f"{type(self).__name__} does not define plot")


def encode_array(values) -> list | dict:
    """An array as plain JSON types.

    Parameters
    ----------
    values : array_like
        Real or complex.

    Returns
    -------
    list or dict
        Nested lists of its shape; for a complex array ``{"real": ..., "imag": ...}``
        of two such lists.
    """
    values = np.asarray(values)
    if np.iscomplexobj(values):
        return {"real": values.real.tolist(), "imag": values.imag.tolist()}
    return values.tolist()


def decode_array(data, dtype=float, ndim: int = 1) -> np.ndarray:
    """The array :func:`encode_array` (or a ``to_dict``) wrote.

    Parameters
    ----------
    data : list or dict
        Nested lists (None read as NaN for floats), or ``{"real", "imag"}``.
    dtype : numpy dtype
        Of the array; a ``{"real", "imag"}`` pair is complex whatever it says.
    ndim : int
        Dimensions wanted: an empty list is read as an array of this many
        dimensions, each of length 0.

    Returns
    -------
    numpy.ndarray
    """
    if isinstance(data, dict):
        return decode_array(data["real"], float, ndim) + 1j * decode_array(data["imag"], float, ndim)
    array = np.array(data, dtype=dtype)
    return array.reshape((0,) * ndim) if array.size == 0 and array.ndim != ndim else array


def decode_arrays(data: dict, dtype=float, ndim: int = 1) -> dict:
    """Name -> array of a dictionary of encoded arrays (:func:`decode_array` on each value).

    Parameters
    ----------
    data : dict
        Name -> encoded array.
    dtype : numpy dtype
        Of every array.
    ndim : int
        Dimensions of every array.

    Returns
    -------
    dict
        Name -> numpy.ndarray, in the order of ``data``.
    """
    return {name: decode_array(values, dtype, ndim) for name, values in data.items()}


#: The modules that define the result classes (each registers its kind on import).
RESULT_MODULES = ("linmstmm.solve", "linmstmm.modes", "linmstmm.fe.result", "linmstmm.damped",
                  "linmstmm.response", "linmstmm.sweep", "linmstmm.studies")


def _import_result_classes() -> None:
    """Import every module of RESULT_MODULES, so that every kind is registered."""
    import importlib

    for name in RESULT_MODULES:
        importlib.import_module(name)
