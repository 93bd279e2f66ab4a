"""scripts/speed_accuracy.py: where its output goes, and its figure labels.

A --quick run takes minutes, so the folder choice is tested on the function
that makes it: a quick run must never write over the committed reports/.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def speed():
    spec = importlib.util.spec_from_file_location("speed_accuracy", ROOT / "scripts" / "speed_accuracy.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quick_run_writes_into_a_new_temporary_folder(speed):
    first, second = speed.output_folder(None, quick=True), speed.output_folder(None, quick=True)
    reports = (ROOT / "reports").resolve()
    for folder in (first, second):
        assert folder.is_dir() and not any(folder.iterdir())
        assert reports not in folder.resolve().parents and folder.resolve() != reports
        folder.rmdir()
    assert first != second


def test_full_run_writes_the_committed_reports(speed):
    assert speed.output_folder(None, quick=False) == ROOT / "reports"


@pytest.mark.parametrize("quick", [True, False])
def test_out_folder_is_used_as_given(speed, tmp_path, quick):
    assert speed.output_folder(tmp_path, quick=quick) == tmp_path


def test_labels_of_coinciding_points_are_merged(speed):
    x, y = [0.047, 0.048, 0.09], [5e-12, 5e-12, 2e-15]
    merged = speed.merged_labels(x, y, ["1e-06", "1e-09", "1e-12"], spans=(2.0, 16.0))
    assert [text for _, _, text in merged] == ["1e-06, 1e-09", "1e-12"]
    apart = speed.merged_labels(x, y, ["1e-06", "1e-09", "1e-12"], spans=(0.01, 0.01))
    assert [text for _, _, text in apart] == ["1e-06", "1e-09", "1e-12"]
