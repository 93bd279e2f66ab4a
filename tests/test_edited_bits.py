"""An edited model (linmstmm.parameters.with_values) is, bit for bit, the model that
load_model reads from the model file with the same numbers written into it (what
with_values promises): every array and number of every record, the points, the
boundary and the damping; and an edit the file would refuse is refused with the
file's message (element, key and words). Checked on the bundled models, on every
firing scene of the launcher and on random models, with edits drawn at random.

The edited file is the model's own TOML document with the values set there,
written without linmstmm; a beam with a moved end is given its old local y as
``y_axis`` (with_values keeps local y as near its old direction as the new axis
allows, as the loader treats a file's ``y_axis``).
"""
from __future__ import annotations

import struct
import tomllib
from pathlib import Path

import numpy as np
import pytest

from linmstmm.model import Beam, ModelError, Rigid, Spring, load_model
from linmstmm.parameters import get_value, parameter_keys, parse_key, with_values
from linmstmm.scenes import bundle_beside, salvo, scene_values
from random_models import KINDS, random_model, to_toml
from test_model import edit
from test_sweep import dump_toml

MODELS = Path(__file__).resolve().parents[1] / "models"
FILES = ["mlrs/mlrs.toml", "launcher2/launcher2.toml", "cantilever_tip_mass.toml",
         "spring_mass_chain.toml", "dashpot_chain.toml"]


def _edited_document(document: dict, model, edits: dict) -> dict:
    """``document`` (the TOML document ``model`` was loaded from) with ``edits``
    (key text -> value) set in it, each edited element written in full."""
    tables = {(kind, t["name"]): t for kind in ("rigid", "beam", "spring") for t in document.get(kind, [])}
    moved, full = set(), set()
    for text, value in edits.items():
        key = parse_key(model, text)
        if key.section == "points":
            document["points"][key.name][key.index[0]] = value
            moved.add(key.name)
        elif key.section == "damping":
            document["damping"] = {"alpha": model.damping[0], "beta": model.damping[1],
                                   **document.get("damping", {}), key.field: value}
        else:
            table = tables[key.section, key.name]
            if key.name not in full:
                _write_out(table, model.element(key.name))
                full.add(key.name)
            _set(table, key, value)
    for beam in model.beams:
        if moved & set(beam.ends):
            tables["beam", beam.name]["y_axis"] = beam.axes[1].tolist()
    return document


def _write_out(table: dict, record) -> None:
    """Write into an element's table every number of its record a file may leave out
    or give in short: the inertia tensor in full, a spring's axes, a beam's ``Ip``
    (a record's inertia is a (3, 3) tensor and its ``Ip`` resolved; an edit acts on those)."""
    if isinstance(record, Rigid):
        table["inertia"] = record.inertia.tolist()
    if isinstance(record, Spring):
        table["axes"] = record.axes.tolist()
    if isinstance(record, Beam):
        table["Ip"] = record.Ip


def _set(table: dict, key, value) -> None:
    """``table[field][index] = value``; both [i][j] and [j][i] of an inertia tensor."""
    if not key.index:
        table[key.field] = value
    elif key.field == "inertia":
        i, j = key.index
        table[key.field][i][j] = table[key.field][j][i] = value
    elif len(key.index) == 1:
        table[key.field][key.index[0]] = value
    else:
        table[key.field][key.index[0]][key.index[1]] = value


def _bits(value):
    """``value`` as comparable bits: arrays by dtype, shape, bytes and writeability;
    floats by their IEEE bytes; containers item by item."""
    if isinstance(value, np.ndarray):
        return ("array", value.dtype.str, value.shape, value.tobytes(), value.flags.writeable)
    if isinstance(value, float):
        return ("float", struct.pack("<d", value))
    if isinstance(value, dict):
        return ("dict", type(value).__name__, [(k, _bits(v)) for k, v in value.items()])
    if isinstance(value, (tuple, list)):
        return (type(value).__name__, [_bits(v) for v in value])
    if isinstance(value, (Rigid, Beam, Spring)):
        return (value.kind, [(f, _bits(getattr(value, f))) for f in value.__dataclass_fields__])
    return ("other", type(value).__name__, value)


def _model_bits(model):
    """Every field of ``model`` but its source file, as bits."""
    return [(f, _bits(getattr(model, f))) for f in model.__dataclass_fields__ if f != "source"]


def _outcome(build):
    """("ok", the model's bits) or ("refused", element, key, message)."""
    try:
        return ("ok", _model_bits(build()))
    except ModelError as error:
        return ("refused", error.element, error.key, error.message)


def _check(model, document: dict, edits: dict, folder: Path):
    """with_values(model, edits) against load_model of the edited file; the outcome."""
    fast = _outcome(lambda: with_values(model, {parse_key(model, k): v for k, v in edits.items()}))
    path = folder / "edited.toml"
    path.write_text(dump_toml(_edited_document(tomllib.loads(dump_toml(document)), model, edits)))
    assert fast == _outcome(lambda: load_model(path)), edits
    return fast[0]


def _drawn_value(rng, value: float, scale: float) -> float:
    """A new value for a number now ``value``: mostly a plausible change (a length
    moved by ~1 % of ``scale``, m), now and then one that breaks something."""
    choice = rng.integers(30)
    breaking = [0.0, -abs(value) - 1.0, np.nan, np.inf, value + 1e3 * scale, 1e-300]
    if choice < len(breaking):
        return float(breaking[choice])
    return float([value, value * rng.uniform(0.8, 1.25), value + 0.01 * scale * rng.normal(),
                  value * (1 + 1e-12), value + 1e-3 * scale, -value][choice % 6])


def _moved_together(rng, model, scale: float) -> dict:
    """Edits moving a point and every point on it (a spring's other end) by the same
    ~1 % of ``scale`` (m): the beams there turn and stretch, the springs stay whole."""
    start = model.points[rng.choice(list(model.points))]
    step = 0.01 * scale * rng.normal(size=3)
    return {f"points.{name}[{i}]": float(position[i] + step[i]) for name, position in model.points.items()
            if np.array_equal(position, start) for i in range(3)}


def _models(folder: Path):
    """(model, its TOML document): the bundled files and random models written to files."""
    for name in FILES:
        path = MODELS / name
        yield name, load_model(path), tomllib.loads(path.read_text())
    for kind in KINDS:
        for seed in range(2):
            text = to_toml(random_model(kind, seed))
            path = folder / f"{kind}_{seed}.toml"
            path.write_text(text)
            yield f"{kind} {seed}", load_model(path), tomllib.loads(text)


def test_an_edited_model_is_the_edited_file_bit_for_bit(tmp_path):
    outcomes = []
    for name, model, document in _models(tmp_path):
        rng = np.random.default_rng(sum(map(ord, name)))
        keys = parameter_keys(model)
        scale = float(np.ptp(np.array(list(model.points.values())), axis=0).max())
        for trial in range(40):  # numbers drawn, a point moved with those on it, or both
            edits = {}
            if trial % 3 != 1:
                chosen = rng.choice(keys, size=min(len(keys), rng.integers(1, 5)), replace=False)
                edits = {k: _drawn_value(rng, get_value(model, parse_key(model, k)), scale) for k in chosen}
            if trial % 3 != 0:
                edits |= _moved_together(rng, model, scale)
            outcomes.append(_check(model, document, edits, tmp_path))
    assert outcomes.count("ok") > 100 and outcomes.count("refused") > 100


@pytest.mark.parametrize("fired", [lambda tube: frozenset(), salvo], ids=["first shot", "salvo"])
def test_every_launcher_scene_is_its_edited_file_bit_for_bit(fired, tmp_path):
    path = MODELS / "mlrs" / "mlrs.toml"
    model, document = load_model(path), tomllib.loads(path.read_text())
    bundle = bundle_beside(model)
    for tube in range(1, 19):
        edits = scene_values(model, tube, fired(tube), bundle)
        assert _check(model, document, edits, tmp_path) == "ok", tube


@pytest.mark.parametrize("x, outcome", [(1.0, "refused"), (-2.0, "ok"), (0.1, "ok")])
def test_a_spring_none_of_whose_ends_moved_is_refused_once_the_model_shrinks(x, outcome, tmp_path):
    """The spring's ends, 2e-9 m apart, coincide within the tolerance of the 2.24 m model
    (2.24e-9 m), not within that of a 1.41 m one: moving the far end of a beam, not an
    end of the spring, changes the verdict."""
    text = edit(("hinge = [2.0, 0.0, 0.0]", "hinge = [2.0, 0.0, 2e-9]"))
    path = tmp_path / "apart.toml"
    path.write_text(text)
    model, document = load_model(path), tomllib.loads(text)
    assert _check(model, document, {"points.root[0]": x}, tmp_path) == outcome
    if outcome == "refused":
        with pytest.raises(ModelError, match="spring 'k1': key 'ends': points 'tip' and 'hinge' do not coincide"):
            with_values(model, {parse_key(model, "points.root[0]"): x})
