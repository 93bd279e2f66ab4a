"""scripts/mlrs_report.py keeps working: its structure text and frequency table on the MLRS model.

The whole report (sweeps, 20-digit reference, timings) takes minutes; this
runs only the pieces that turn the model into the structure section and the
frequency table, so an API change in linmstmm breaks a test, not the next
regeneration of reports/mlrs.md.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "scripts" / "mlrs_report.py"


@pytest.fixture(scope="module")
def report():
    spec = importlib.util.spec_from_file_location("mlrs_report", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def model(report):
    return report.load()


def test_structure_text_is_the_papers_shape(report, model):
    topology, structure = report.structure(model)
    assert structure.root.label == "muzzle"
    assert len(structure.tips) == 7 and len(structure.cuts) == 1
    assert structure.ubar_order == 60
    assert (len(structure.block_rows), len(structure.block_columns)) == (9, 9)
    text = report.structure_text(model)
    assert text.startswith("root: muzzle")
    assert "order of Ubar_all: 60" in text
    assert "U_all Z_all = 0, block layout:" in text


def test_frequency_table(report, model):
    rows, mstmm, fe = report.frequency_rows(model, count=6)
    assert [row["mode"] for row in rows] == [1, 2, 3, 4, 5, 6]
    assert all(abs(row["difference"]) < 1e-7 for row in rows)
    assert all(2.0 < row["mstmm"] < 6.0 for row in rows)
    assert [row["paper_test"] for row in rows] == list(report.PAPER_TEST_HZ)
    table = report.frequency_table(rows).splitlines()
    assert len(table) == 2 + 6
    assert all(line.count("|") == table[0].count("|") for line in table)
    assert "| 5 |" in table[6] and "| 5.01 | – |" in table[6]  # the paper has no MSTMM value for mode 5


def test_mode_descriptions_cover_the_drawn_modes(report):
    assert len(report.MODE_DESCRIPTIONS) == report.MODES
