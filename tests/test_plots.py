"""Figures (linmstmm.plot), the commands modes / scan / response / frf and the scripts.

Every figure command must write its files: PNGs and GIFs are checked by
their signatures (and the GIF's frame count). The commands run through
``cli.main``; one subprocess test runs the real command line.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from builders import fixed, single_beam_model
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from linmstmm import cli
from linmstmm.compare import align_eigenspaces
from linmstmm.label_layout import AROUND, line_samples, place_label
from linmstmm.mode_figure import _GIF_COLORS, _mode_canvas, _scene, convex_hull
from linmstmm.model import load_model
from linmstmm.modes import mac_matrix, mode_shapes
from linmstmm.plot import (AMPLITUDE, _line_styles, animate_mode, frf_figure, plot_frf, plot_mac, plot_mode,
                           plot_response, plot_scan, significant_components)
from linmstmm.response import PointLoad, frf, modal_response, step

ROOT = Path(__file__).resolve().parents[1]
CANTILEVER = str(ROOT / "models/cantilever_tip_mass.toml")
CHAIN = str(ROOT / "models/spring_mass_chain.toml")
STEP = str(ROOT / "models/loads/cantilever_step.toml")
PNG = b"\x89PNG\r\n\x1a\n"
GIF = (b"GIF87a", b"GIF89a")


def is_png(path) -> bool:
    return Path(path).read_bytes()[:8] == PNG


@pytest.fixture(scope="module")
def cantilever():
    model = load_model(CANTILEVER)
    return model, mode_shapes(model, 4, normalization="max")


@pytest.fixture(scope="module")
def chain():
    model = load_model(CHAIN)
    return model, mode_shapes(model, 3)


# --- the figure functions -------------------------------------------------------------

@pytest.mark.parametrize("which", ["cantilever", "chain"])
def test_mode_figure_is_a_png(tmp_path, request, which):
    model, modes = request.getfixturevalue(which)
    plot_mode(modes, model, 0, tmp_path / "mode.png")
    assert is_png(tmp_path / "mode.png")


def test_largest_drawn_translation_is_a_tenth_of_the_model(cantilever):
    model, modes = cantilever
    scene = _scene(modes, model, 2)
    motion = np.concatenate([scene.segment_motion.reshape(-1, 3), *scene.body_motion, scene.marker_motion])
    drawn = np.linalg.norm(scene.scale * motion, axis=-1).max()
    assert drawn == pytest.approx(AMPLITUDE * 2.0)  # the arm is 2 m long
    assert "mode 3" in scene.title and "50.899" in scene.title
    assert f"drawn × {scene.scale:.3g}" in scene.title and "model's size (2 m)" in scene.title


def test_mode_figure_has_three_orthographic_views_and_an_isometric_one(chain):
    """Each view shows the two coordinates it names, at one scale; rigid bodies are filled outlines."""
    model, modes = chain
    scene = _scene(modes, model, 0)
    figure, views = _mode_canvas(scene)
    assert [v.view.labels for v in views[:3]] == [("x [m]", "z [m]"), ("y [m]", "z [m]"), ("x [m]", "y [m]")]
    assert views[3].view.labels is None and "isometric" in views[3].view.title
    point = np.array([1.0, 2.0, 3.0])
    assert [tuple(v.view.project(point)) for v in views[:3]] == [(1.0, 3.0), (2.0, 3.0), (1.0, 2.0)]
    iso = views[3].view.project(np.eye(3))  # the unit axes on screen: a projection along (1, -1, 1)
    towards_viewer = np.array([1.0, -1.0, 1.0]) / np.sqrt(3)
    np.testing.assert_allclose(iso @ iso.T, np.eye(3) - np.outer(towards_viewer, towards_viewer), atol=1e-15)
    assert views[3].view.depth(towards_viewer) == pytest.approx(1.0)
    figure.canvas.draw()
    for view in views:  # true shapes: one metre is as long across as up
        across, up = np.diff(view.axes.transData.transform([[0, 0], [1, 1]]), axis=0)[0]
        assert across == pytest.approx(up, rel=1e-6)
    assert len(views[0].hulls.get_paths()) == len(model.rigids) == 2
    assert figure.axes[-1].get_xlabel() == "displacement, fraction of largest"  # the colour bar


def test_convex_hull():
    square = [[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.5, 0]]
    hull = convex_hull(square)
    assert sorted(map(tuple, hull)) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    following = np.roll(hull, -1, axis=0)
    area = 0.5 * (hull[:, 0] * following[:, 1] - hull[:, 1] * following[:, 0]).sum()
    assert area == pytest.approx(1.0)  # counter-clockwise
    assert sorted(map(tuple, convex_hull([[2, 2], [0, 0], [1, 1], [1, 1]]))) == [(0, 0), (2, 2)]
    assert convex_hull([[1, 1]]).tolist() == [[1, 1]]


def test_rotation_only_mode_is_drawn_undeformed(tmp_path):
    """A shaft's torsion mode moves nothing off its axis."""
    model = single_beam_model(fixed(), None, Iz=1.0, Iy=1.0, J=2e-7, Ip=4e-7, axial=False)
    modes = mode_shapes(model, 1)
    scene = _scene(modes, model, 0)
    assert scene.scale == 0 and "rotation only" in scene.title
    plot_mode(modes, model, 0, tmp_path / "torsion.png")
    assert is_png(tmp_path / "torsion.png")


def test_mode_index_out_of_range(cantilever, tmp_path):
    model, modes = cantilever
    with pytest.raises(IndexError):
        plot_mode(modes, model, modes.omega.size, tmp_path / "none.png")


def test_animation_is_a_wide_small_gif_with_every_frame(chain, tmp_path):
    model, modes = chain
    animate_mode(modes, model, 1, tmp_path / "mode.gif", frames=5)
    assert (tmp_path / "mode.gif").read_bytes()[:6] in GIF
    with Image.open(tmp_path / "mode.gif") as image:
        assert image.n_frames == 5 and image.width >= 900 and image.mode == "P"
        colours = set()
        for frame in range(image.n_frames):
            image.seek(frame)
            colours |= {colour for _, colour in image.convert("RGB").getcolors(maxcolors=1 << 16)}
    assert len(colours) <= _GIF_COLORS  # one small palette for every frame
    assert (tmp_path / "mode.gif").stat().st_size < 150_000


def test_scan_figure(tmp_path):
    omegas = np.linspace(1.0, 100.0, 200)
    values = np.cos(omegas / 10)
    roots = 10 * (np.pi / 2 + np.pi * np.arange(3))
    plot_scan(omegas, np.sign(values), np.log(np.abs(values)), roots,
              np.searchsorted(roots, omegas, side="right"), tmp_path / "scan.png")
    assert is_png(tmp_path / "scan.png")


@pytest.fixture(scope="module")
def tip_response(cantilever):
    model, modes = cantilever
    load = PointLoad("tip", np.array([0.0, 0.0, -100.0]), np.zeros(3), step(0.01))
    return modal_response(modes, [load], np.linspace(0.0, 0.3, 301), ["tip", "root"])


@pytest.mark.parametrize("quantity", ["displacement", "acceleration"])
def test_response_figure(tip_response, tmp_path, quantity):
    plot_response(tip_response, tmp_path / "response.png", quantity)
    assert is_png(tmp_path / "response.png")


def test_response_figure_rejects_an_unknown_quantity(tip_response, tmp_path):
    with pytest.raises(ValueError, match="quantity"):
        plot_response(tip_response, tmp_path / "response.png", "jerk")


def test_frf_figure_and_its_significant_components(cantilever, tmp_path):
    model, modes = cantilever
    result = frf(modes, "tip", np.r_[0.0, 0.0, 1.0, 0.0, 0.0, 0.0], np.linspace(1.0, 100.0, 300), ["tip"])
    assert significant_components(result.receptance) == [(0, 2), (0, 4)]  # tip z and its slope ry
    plot_frf(result, tmp_path / "frf.png", modes.frequencies_hz)
    assert is_png(tmp_path / "frf.png")


def _curves(axis):
    return [line for line in axis.get_lines() if not line.get_label().startswith("_")]


def test_frf_figure_has_one_magnitude_axis_per_unit(cantilever):
    """Translations (m/N) and rotations (rad/N) never share an axis; each line names point and direction."""
    _, modes = cantilever
    result = frf(modes, "tip", np.r_[0.0, 1.0, 1.0, 0.0, 0.0, 0.0], np.linspace(1.0, 100.0, 100), ["tip"])
    translation, rotation, phase = frf_figure(result).axes
    assert translation.get_ylabel().endswith("[m/N]") and rotation.get_ylabel().endswith("[rad/N]")
    assert phase.get_ylabel() == "phase [deg]" and len(phase.get_lines()) == 4
    for axis, directions in ((translation, "xyz"), (rotation, ("rx", "ry", "rz"))):
        labels = [line.get_label().split() for line in _curves(axis)]
        assert labels and all(point in result.points and direction in directions for point, direction in labels)
    assert [line.get_label() for line in _curves(translation)] == ["tip y", "tip z"]
    only_forces = frf(modes, "tip", np.r_[0.0, 0.0, 1.0, 0.0, 0.0, 0.0], np.linspace(1.0, 100.0, 50), ["tip"])
    only_forces.receptance[:, :, 3:] = 0  # translations alone: one magnitude axis and the phase
    assert len(frf_figure(only_forces, load_unit="N").axes) == 2


def test_frf_lines_differ_in_colour_or_style():
    """Up to 60 points × 6 directions, no two lines look alike."""
    lines = [(p, c) for p in range(60) for c in range(6)]
    styles = _line_styles(lines)
    looks = {(c < 3, s["color"], s["ls"], s["marker"]) for (p, c), s in styles.items()}  # c < 3: its axis
    assert len(looks) == len(lines)


def test_mac_figure(tmp_path):
    plot_mac(np.eye(3) * 0.9 + 0.05, tmp_path / "mac.png", [1.0, 2.0, 3.0], [1.1, 2.1, 3.1])
    assert is_png(tmp_path / "mac.png")


def test_aligned_eigenspace_recovers_the_reference_modes():
    rng = np.random.default_rng(5)
    reference = rng.normal(size=(3, 12))
    turn = np.linalg.qr(rng.normal(size=(2, 2)))[0]
    other = np.vstack([turn @ reference[:2], 2.0 * reference[2]])  # modes 1, 2: one repeated frequency
    assert np.diag(mac_matrix(reference, other))[:2].min() < 0.999
    aligned = align_eigenspaces(reference, other, [5.0, 5.0, 7.0])
    np.testing.assert_allclose(np.diag(mac_matrix(reference, aligned)), 1.0, rtol=1e-12)


# --- the commands ---------------------------------------------------------------------

@pytest.fixture
def run(capsys):
    """cli.main: (status, stdout, stderr)."""

    def invoke(*argv):
        status = cli.main([str(a) for a in argv])
        captured = capsys.readouterr()
        return status, captured.out, captured.err
    return invoke


def test_modes_json_plots_animations_uff_and_mac(run, tmp_path):
    status, out, _ = run("modes", CANTILEVER, "--count", "2", "--json", "--plot", tmp_path / "figs",
                         "--animate", "--uff", tmp_path / "modes.uff", "--mac-fe")
    assert status == 0
    data = json.loads(out)
    for key in ("model", "frequencies_hz", "rigid_body_modes", "modal_mass", "modal_stiffness",
                "mass_orthogonality_error", "stiffness_orthogonality_error", "point_displacements",
                "points", "mac_fe", "files"):
        assert key in data
    assert len(data["frequencies_hz"]) == 2 and data["mass_orthogonality_error"] < 1e-9
    assert len(data["point_displacements"]["tip"]) == 2 and len(data["point_displacements"]["tip"][0]) == 6
    assert min(np.diag(data["mac_fe"]["matrix"])) > 0.9999
    pngs, gifs = sorted((tmp_path / "figs").glob("*.png")), sorted((tmp_path / "figs").glob("*.gif"))
    assert [p.name for p in pngs] == ["mac_fe.png", "mode_1.png", "mode_2.png"] and all(map(is_png, pngs))
    assert len(gifs) == 2 and all(g.read_bytes()[:6] in GIF for g in gifs)
    assert (tmp_path / "modes.uff").read_text().startswith("    -1\n    15\n")


def test_modes_table(run):
    status, out, _ = run("modes", CHAIN, "--count", "3")
    assert status == 0
    assert "spring-mass chain" in out and "modal mass" in out and "orthogonality error" in out


def test_scan_json_and_figure(run, tmp_path):
    status, out, _ = run("scan", CANTILEVER, "--fmax", "60", "--points", "300", "--plot",
                         tmp_path / "scan.png", "--json")
    assert status == 0
    data = json.loads(out)
    assert data["ubar_order"] == 12 and data["points"] == 300
    np.testing.assert_allclose(data["frequencies_hz"], [6.7535653, 6.7535653, 50.899157, 50.899157], rtol=1e-7)
    assert is_png(tmp_path / "scan.png")


def test_response_json_and_figure(run, tmp_path):
    status, out, _ = run("response", CANTILEVER, STEP, "--json", "--plot", tmp_path / "step.png")
    assert status == 0
    data = json.loads(out)
    for key in ("times", "points", "displacement", "velocity", "acceleration", "peaks", "peak_times"):
        assert key in data
    assert data["points"] == ["tip"]
    # undamped step: the tip swings to about twice its static deflection, 6.35 mm + beam mass
    assert 0.012 < data["peaks"]["tip"][2] < 0.0135
    assert is_png(tmp_path / "step.png")


def test_response_table(run):
    status, out, _ = run("response", CANTILEVER, STEP)
    assert status == 0 and "peak |displacement|" in out and "tip" in out


def test_frf_json_and_figure(run, tmp_path):
    status, out, _ = run("frf", CANTILEVER, "--point", "tip", "--direction", "z", "--fmax", "60",
                         "--frequencies", "200", "--response-points", "tip", "root", "--json",
                         "--plot", tmp_path / "frf.png")
    assert status == 0
    data = json.loads(out)
    for key in ("load", "frequencies_hz", "modes_in_sum", "excitation_hz", "points", "receptance"):
        assert key in data
    assert data["points"] == ["tip", "root"] and len(data["excitation_hz"]) == 200
    static = 2.0**3 / (3 * 2.1e11 * 2e-7)  # tip flexibility, m/N; the sum has only two z modes
    assert data["receptance"]["tip"]["real"][0][2] == pytest.approx(static, rel=3e-3)
    assert is_png(tmp_path / "frf.png")


def test_frf_table(run):
    status, out, _ = run("frf", CANTILEVER, "--point", "tip", "--direction", "ry", "--fmax", "20",
                         "--frequencies", "50")
    assert status == 0 and "per N m" in out and "undamped" in out


@pytest.mark.parametrize("argv, key", [
    (("modes", CANTILEVER, "--animate"), "--animate"),
    (("modes", CANTILEVER, "--plot", "{tmp}/file.txt/figs"), "--plot"),
    (("modes", CANTILEVER, "--uff", "{tmp}/missing/modes.uff"), "--uff"),
    (("modes", CANTILEVER, "--fmax", "1"), "--fmax"),
    (("scan", CANTILEVER, "--fmax", "10", "--plot", "{tmp}/missing/scan.png"), "--plot"),
    (("scan", CANTILEVER, "--plot", "{tmp}/scan.png"), "--fmax"),
    (("scan", CANTILEVER, "--fmax", "-1", "--plot", "{tmp}/scan.png"), "--fmax"),
    (("response", CANTILEVER, "{tmp}/nowhere.toml"), "nowhere.toml"),
    (("response", CHAIN, STEP), "tip"),
    (("frf", CANTILEVER, "--point", "tipp", "--direction", "z", "--fmax", "10"), "--point"),
    (("frf", CANTILEVER, "--point", "tip", "--direction", "w", "--fmax", "10"), "--direction"),
    (("frf", CANTILEVER, "--point", "tip", "--direction", "z", "--fmax", "10",
      "--response-points", "nowhere"), "--response-points"),
    (("frf", CANTILEVER, "--point", "tip", "--direction", "z", "--fmax", "1"), "--fmax"),
])
def test_bad_input_exits_2_with_one_line(run, tmp_path, argv, key):
    (tmp_path / "file.txt").write_text("not a folder")
    status, _, err = run(*[a.format(tmp=tmp_path) for a in argv])
    assert status == 2
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err and key in err


def test_modes_subcommand_end_to_end(tmp_path):
    result = subprocess.run([sys.executable, "-m", "linmstmm", "modes", CANTILEVER, "--count", "1",
                             "--json", "--plot", str(tmp_path)], cwd=ROOT, capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["frequencies_hz"][0] == pytest.approx(6.7535653, rel=1e-7)
    assert is_png(tmp_path / "mode_1.png")


# --- the scripts ----------------------------------------------------------------------

@pytest.mark.parametrize("script, words", [
    ("frf_sweep.py", ["natural frequencies", "largest |H|"]),
    ("firing_impulse.py", ["peak |displacement|", "muzzle", "tube_rear"]),
])
def test_script_writes_its_figure(tmp_path, script, words):
    figure = tmp_path / "figure.png"
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / script), "--plot", str(figure)],
                            cwd=tmp_path, capture_output=True, text=True, timeout=180)
    assert result.returncode == 0, result.stderr
    assert all(word in result.stdout for word in words)
    assert is_png(figure)


def test_a_label_takes_the_first_clear_place():
    """A line across the place above the anchor sends the label to the next place; a box taken, further."""
    figure = Figure(figsize=(4, 3))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot(xlim=(0, 10), ylim=(0, 10))
    line = [[0, 5.3], [10, 5.3]]  # a few points above the anchor (5, 5)
    samples = line_samples(axes, [line])
    assert np.diff(np.sort(samples[:, 0])).max() <= 2.0 + 1e-9  # at most 2 px apart
    taken = []
    first = place_label(axes, "name", (5, 5), samples, taken)
    assert first.get_anncoords() == "offset points" and first.xyann[1] < 0  # below the line
    assert not taken[0].count_contains(samples)
    second = place_label(axes, "name", (5, 5), samples, taken)
    assert not second.get_window_extent().overlaps(taken[0])
    everywhere = place_label(axes, "name", (5, 5), samples, taken, places=AROUND[:1])
    assert everywhere.xyann == AROUND[0][0]  # nothing clear: the first place
