"""Universal file output (linmstmm.uff) read back by a small fixed-column reader.

The reader below knows only the SDRC record layouts: dataset 15 records
FORMAT(4I10, 1P3E13.5), dataset 55 records 1–5 (40A2), 6 (6I10), 7 (8I10),
8 (6E13.5), then per node 9 (I10) and 10 (6E13.5). It slices fields by
column, as Fortran would, so a misplaced column fails even where splitting on
blanks would not.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from builders import single_beam_model

from linmstmm.model import load_model
from linmstmm.modes import mode_shapes
from linmstmm.uff import write_uff

ROOT = Path(__file__).resolve().parents[1]
E13 = 13
I10 = 10
#: E13.5 keeps six significant digits.
RTOL = 6e-6


def fields(line: str, width: int, count: int) -> list[str]:
    """``count`` fixed-width fields of ``line``; the line must hold exactly them."""
    assert len(line) == width * count, f"record {line!r} is not {count} fields of {width}"
    return [line[i * width:(i + 1) * width] for i in range(count)]


def datasets(text: str) -> list[tuple[int, list[str]]]:
    """(number, record lines) of every dataset between ``-1`` delimiters (I6)."""
    lines, found = text.splitlines(), []
    i = 0
    while i < len(lines):
        assert lines[i] == "    -1", f"line {i + 1}: expected a delimiter, got {lines[i]!r}"
        end = lines.index("    -1", i + 1)
        assert len(lines[i + 1]) == 6
        found.append((int(lines[i + 1]), lines[i + 2:end]))
        i = end + 1
    return found


def reals(line: str, count: int) -> list[float]:
    """E13.5 fields; each keeps a leading blank (two-digit exponent), so blank-splitting readers work too."""
    found = fields(line, E13, count)
    assert all(field[0] == " " for field in found), line
    return [float(field) for field in found]


def read_nodes(records: list[str]) -> dict[int, np.ndarray]:
    nodes = {}
    for record in records:
        assert len(record) == 4 * I10 + 3 * E13
        label, definition, displacement, _ = (int(f) for f in fields(record[:4 * I10], I10, 4))
        assert definition == 0 and displacement == 0
        nodes[label] = np.array(reals(record[4 * I10:], 3))
    return nodes


def read_mode(records: list[str]) -> dict:
    ids = records[:5]
    assert all(len(line) == 80 for line in ids)
    definition = [int(f) for f in fields(records[5], I10, 6)]
    integers = [int(f) for f in fields(records[6], I10, 4)]
    header = reals(records[7], 4)
    values = {}
    for label_line, data_line in zip(records[8::2], records[9::2]):
        values[int(fields(label_line, I10, 1)[0])] = np.array(reals(data_line, 6))
    assert len(records) == 8 + 2 * len(values)
    return {"ids": ids, "definition": definition, "integers": integers, "reals": header, "values": values}


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    model = load_model(ROOT / "models/mlrs/mlrs.toml")
    modes = mode_shapes(model, 3, normalization="max")
    path = tmp_path_factory.mktemp("uff") / "mlrs.uff"
    labels = write_uff(modes, model, path)
    return model, modes, labels, datasets(path.read_text(encoding="ascii"))


def test_geometry_then_one_dataset_55_per_mode(written):
    _, modes, _, found = written
    assert [number for number, _ in found] == [15] + [55] * modes.omega.size


def test_nodes_round_trip(written):
    model, _, labels, found = written
    nodes = read_nodes(found[0][1])
    assert list(labels.values()) == list(range(1, len(model.points) + 1))
    for point, label in labels.items():
        np.testing.assert_allclose(nodes[label], model.points[point], rtol=RTOL, atol=1e-12)


def test_modes_round_trip(written):
    model, modes, labels, found = written
    for k, (_, records) in enumerate(found[1:]):
        mode = read_mode(records)
        assert mode["ids"][0].rstrip() == model.name
        assert mode["definition"] == [1, 2, 3, 8, 2, 6]  # structural, normal mode, 6 DOF, displacement, real
        assert mode["integers"] == [2, 4, 1, k + 1]
        frequency, modal_mass, viscous, hysteretic = mode["reals"]
        assert frequency == pytest.approx(modes.frequencies_hz[k], rel=RTOL)
        assert modal_mass == pytest.approx(modes.modal_mass[k], rel=RTOL)
        assert viscous == 0 and hysteretic == 0  # the model has no [damping]
        assert sorted(mode["values"]) == sorted(labels.values())
        for point, label in labels.items():
            want = modes.point_displacements[point][k]
            np.testing.assert_allclose(mode["values"][label], want, rtol=RTOL, atol=1e-99)


def test_damping_ratio_and_rigid_body_modes(tmp_path):
    """A free beam: six rigid-body modes (ζ = 0), then ζ_k = (α + β ω_k²) / (2 ω_k)."""
    alpha, beta = 0.4, 2e-5
    model = dataclasses.replace(single_beam_model(None, None, Iz=2e-7, Iy=5e-7), damping=(alpha, beta))
    modes = mode_shapes(model, 2)
    write_uff(modes, model, tmp_path / "free.uff")
    found = datasets((tmp_path / "free.uff").read_text())
    assert len(found) == 1 + 6 + 2
    for k, (_, records) in enumerate(found[1:]):
        frequency, _, ratio, _ = read_mode(records)["reals"]
        omega = modes.omega[k]
        want = 0.0 if omega == 0 else (alpha + beta * omega**2) / (2 * omega)
        assert ratio == pytest.approx(want, rel=RTOL)
        assert (frequency == 0) == (omega == 0)


def test_values_too_small_for_two_exponent_digits_are_zero(tmp_path):
    model = load_model(ROOT / "models/cantilever_tip_mass.toml")
    modes = mode_shapes(model, 1)
    tiny = dict(modes.point_displacements, root=np.full_like(modes.point_displacements["root"], -3e-120))
    write_uff(dataclasses.replace(modes, point_displacements=tiny), model, tmp_path / "tiny.uff")
    mode = read_mode(datasets((tmp_path / "tiny.uff").read_text())[1][1])
    assert np.all(mode["values"][1] == 0)


def test_pyuff_reads_it(written, tmp_path):
    """pyuff (the reader fit uses for measured modes) reads the same values."""
    import pyuff
    model, modes, labels, _ = written
    path = tmp_path / "again.uff"
    write_uff(modes, model, path)
    sets = pyuff.UFF(str(path)).read_sets()
    assert [s["type"] for s in sets] == [15] + [55] * modes.omega.size
    np.testing.assert_allclose(sets[0]["x"], [xyz[0] for xyz in model.points.values()], rtol=RTOL, atol=1e-12)
    for k, mode in enumerate(sets[1:]):
        assert mode["mode_n"] == k + 1 and mode["n_data_per_node"] == 6
        assert mode["freq"] == pytest.approx(modes.frequencies_hz[k], rel=RTOL)
        got = np.column_stack([mode[f"r{i}"] for i in range(1, 7)])
        np.testing.assert_allclose(got, modes.shape_matrix(labels).reshape(modes.omega.size, -1, 6)[k],
                                   rtol=RTOL, atol=1e-99)
