"""Mode shapes as a universal file (UFF): geometry as dataset 15, modes as dataset 55;
written by :func:`write_uff`, read back (measured modes for a fit) by :func:`read_uff_modes`.

The file opens with one dataset 15 (nodes) holding the model's connection
points, numbered 1, 2, … in the model's point order, followed by one
dataset 55 (data at nodes) per mode: real normal-mode data with six values
per node (ux, uy, uz, θx, θy, θz in the global frame). Record layouts follow
the SDRC / I-DEAS universal file descriptions, as read by pyuff and modal
test software:

Every dataset is delimited by ``-1`` lines (I6) and starts with its number (I6).

Dataset 15, one record per node, FORMAT(4I10, 1P3E13.5): node label,
definition coordinate system (0 = global), displacement coordinate system
(0), colour, x, y, z.

Dataset 55, per mode:

* records 1–5, FORMAT(40A2): five 80-character ID lines;
* record 6, FORMAT(6I10): model type 1 (structural), analysis type 2 (normal
  mode), data characteristic 3 (6 DOF global translation & rotation), specific
  data type 8 (displacement), data type 2 (real), 6 values per node;
* record 7, FORMAT(8I10): 2 integer and 4 real values follow, load case 1,
  mode number;
* record 8, FORMAT(6E13.5): frequency (Hz), modal mass, modal viscous damping
  ratio, modal hysteretic damping ratio (0);
* records 9 and 10 per node: FORMAT(I10) node label, FORMAT(6E13.5) the six values.

Units are SI (m, rad, kg). The modal mass belongs to the shapes as written
(``ModalResult.normalization``); the viscous damping ratio is
ζ_k = (α + β ω_k²) / (2 ω_k) for the model's ``[damping]`` (0 without it, and
for rigid-body modes).
"""
from __future__ import annotations

import numpy as np

from linmstmm.model import Model, ModelError
from linmstmm.modes import ModalResult
from linmstmm.response import modal_damping

#: Record 6 of dataset 55: structural, normal mode, 6 DOF global translation &
#: rotation, displacement, real, six values per node.
MODE_DEFINITION = (1, 2, 3, 8, 2, 6)
#: Colour of the nodes in dataset 15.
NODE_COLOR = 1
#: Values this small are written as 0: E13.5 has room for two exponent digits only.
_SMALLEST = 1e-99
#: A dataset-15 node is at its point where the two are this close, relative to the model's size
#: (plus E13.5's rounding, six significant digits, of the coordinates themselves).
SAME_PLACE = 1e-4


def write_uff(result: ModalResult, model: Model, path) -> dict[str, int]:
    """Write the modes of ``result`` (of ``model``) to the universal file ``path``.

    Returns the node label of every point (point name -> label, from 1).
    """
    labels = {point: label for label, point in enumerate(model.points, start=1)}
    ratios = _damping_ratios(result.omega, model.damping)
    lines = _dataset(15, [_integers(label, 0, 0, NODE_COLOR) + _reals(model.points[point])
                          for point, label in labels.items()])
    for k in range(result.omega.size):
        lines += _dataset(55, _mode_records(result, model, k, labels, ratios[k]))
    with open(path, "w", encoding="ascii") as file:
        file.write("\n".join(lines) + "\n")
    return labels


def _mode_records(result: ModalResult, model: Model, k: int, labels: dict, ratio: float) -> list[str]:
    """Records 1–10 of dataset 55 for mode ``k``."""
    frequency = result.frequencies_hz[k]
    ids = [model.name,
           f"mode {k + 1}: {frequency:.9g} Hz, {result.normalization} normalisation",
           "linmstmm: MSTMM normal modes at the connection points, SI units (m, rad, kg)",
           "NONE", "NONE"]
    records = [_text(line) for line in ids]
    records += [_integers(*MODE_DEFINITION), _integers(2, 4, 1, k + 1),
                _reals([frequency, result.modal_mass[k], ratio, 0.0])]
    for point, label in labels.items():
        records += [_integers(label), _reals(result.point_displacements[point][k])]
    return records


def _damping_ratios(omega: np.ndarray, damping) -> np.ndarray:
    """(n,) viscous damping ratios c_k / (2 ω_k); 0 for rigid-body modes."""
    rate = modal_damping(omega, damping)
    return np.divide(rate, 2 * omega, out=np.zeros_like(omega), where=omega > 0)


def _dataset(number: int, records: list[str]) -> list[str]:
    """Lines of one dataset: delimiter, number, records, delimiter."""
    return [f"{-1:6d}", f"{number:6d}", *records, f"{-1:6d}"]


def _text(line: str) -> str:
    """An 80-character ID line (FORMAT 40A2), ASCII only."""
    return line.encode("ascii", "replace").decode("ascii")[:80].ljust(80)


def _integers(*values) -> str:
    """One record of I10 fields."""
    return "".join(f"{int(value):10d}" for value in values)


def _reals(values) -> str:
    """One record of E13.5 fields (at most six)."""
    values = np.asarray(values, dtype=float)
    values = np.where(np.abs(values) < _SMALLEST, 0.0, values)
    return "".join(f"{value:13.5E}" for value in values)


def read_uff_modes(path, model: Model) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Modes of a universal file (datasets 55, normal modes) on the points of ``model``.

    Nodes are the model's points in order, labelled 1, 2, … as :func:`write_uff`
    numbers them; a dataset 15 in the file must put each node it lists at its
    point (to SAME_PLACE of the model's size, and the rounding of E13.5), so that a file of another model
    is refused instead of misread. Each mode gives the components its dataset
    holds per node: ux, uy, uz (and θx, θy, θz with six values per node).

    Parameters
    ----------
    path : str or Path
        The universal file.
    model : Model
        The model whose points the nodes are.

    Returns
    -------
    tuple
        (frequencies (m,) Hz in the file's order, shapes (m, c), columns: c pairs
        (point, direction index 0-5)). E13.5 holds six significant digits.

    Raises
    ------
    ModelError
        Naming the file: not readable as UFF, no dataset 55, a node that is no point
        of the model or lies elsewhere, modes with different nodes or components.
    """
    import pyuff

    where = str(path)
    try:
        datasets = pyuff.UFF(where).read_sets()
    except Exception as error:  # pyuff raises bare Exceptions for a file it cannot parse
        raise ModelError(where, f"cannot be read as a universal file: {error}") from None
    datasets = datasets if isinstance(datasets, list) else [datasets]
    points = list(model.points)
    for nodes in (d for d in datasets if d.get("type") == 15):
        _check_nodes(where, model, points, nodes)
    modes = [d for d in datasets if d.get("type") == 55]
    if not modes:
        raise ModelError(where, "holds no dataset 55 (modes at nodes)")
    columns = _mode_columns(where, points, modes[0])
    per_node = len(columns) // len(modes[0]["node_nums"])
    for mode in modes[1:]:
        if _mode_columns(where, points, mode) != columns:
            raise ModelError(where, f"mode {mode.get('mode_n')}: other nodes or components than the first mode's")
    shapes = [np.column_stack([mode[f"r{d + 1}"] for d in range(per_node)]).ravel() for mode in modes]  # node by node
    return np.array([float(mode["freq"]) for mode in modes]), np.array(shapes), columns


def _check_nodes(where: str, model: Model, points: list, nodes: dict) -> None:
    """ModelError unless every node of dataset 15 ``nodes`` is one of the points, at its place."""
    places = np.array([*model.points.values()], dtype=float)
    size = max(float(np.ptp(places, axis=0).max()) if len(places) else 0.0, np.finfo(float).tiny)
    for label, *xyz in zip(nodes["node_nums"], nodes["x"], nodes["y"], nodes["z"]):
        index = int(label) - 1
        if not 0 <= index < len(points):
            raise ModelError(where, f"node {int(label)} is no point of the model (nodes 1-{len(points)} are its "
                                    "points in order)", key="node")
        rounding = 1e-5 * np.abs(places[index]).max()
        if np.abs(np.array(xyz) - places[index]).max() > SAME_PLACE * size + rounding:
            raise ModelError(where, f"node {int(label)} is at {list(xyz)}, its point {points[index]!r} at "
                                    f"{list(places[index])}: the file is of another model", key="node")


def _mode_columns(where: str, points: list, mode: dict) -> tuple:
    """(point, direction) of every value of dataset 55 ``mode``, node after node."""
    per_node = int(mode.get("n_data_per_node", 3))
    if per_node not in (3, 6):
        raise ModelError(where, f"mode {mode.get('mode_n')}: {per_node} values per node (3 or 6 expected)")
    labels = [int(label) for label in mode["node_nums"]]
    if any(not 1 <= label <= len(points) for label in labels):
        raise ModelError(where, f"mode {mode.get('mode_n')}: a node that is no point of the model "
                                f"(nodes 1-{len(points)} are its points in order)", key="node")
    return tuple((points[label - 1], d) for label in labels for d in range(per_node))
