"""scripts/speed_accuracy.py: where its output goes, and its figure labels.

A --quick run takes minutes, so the folder choice is tested on the function
that makes it: a quick run must never write over the committed reports/.
"""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from linmstmm.label_layout import line_samples

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


def test_setting_labels_stay_off_the_lines_and_each_other(speed, tmp_path):
    """The trade figure's labels, on a crowded synthetic family like the FE meshes of the beam model."""
    meshes = [2, 4, 8, 16, 32, 64, 128, 256]
    seconds = [0.003, 0.0035, 0.0045, 0.012, 0.0075, 0.0085, 0.011, 0.015]
    points = [dict(family="FE fixed mesh", setting=f"elements_per_beam={n}", seconds=t, error=0.5 / n ** 2.5)
              for n, t in zip(meshes, seconds)]
    points += [dict(family="MSTMM xtol", setting=f"xtol={x:g}", seconds=0.0075 * 1.02, error=e)
               for x, e in ((1e-6, 1e-3), (1e-9, 1e-6))]  # a vertical line just right of mesh 32
    figure, axes = speed.plt.subplots(figsize=(12.5, 6.5))
    for family in ("FE fixed mesh", "MSTMM xtol"):
        chosen = [p for p in points if p["family"] == family]
        axes.plot([p["seconds"] for p in chosen], [p["error"] for p in chosen], **speed.STYLES[family])
    axes.set_xscale("log")
    axes.set_yscale("log")
    speed.label_settings(axes, points, spans=(1.0, 5.0))
    figure.canvas.draw()
    labels = [text for text in axes.texts if text.get_text() in {str(n) for n in meshes}]
    assert len(labels) == len(meshes)
    samples = line_samples(axes, [line.get_xydata() for line in axes.get_lines()])
    boxes = [label.get_window_extent() for label in labels]
    assert not any(box.count_contains(samples) for box in boxes)
    assert not any(a.overlaps(b) for i, a in enumerate(boxes) for b in boxes[i + 1:])
    speed.plt.close(figure)
