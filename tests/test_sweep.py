"""Parameter studies (``linmstmm sweep``, :mod:`linmstmm.sweep`, :mod:`linmstmm.parameters`).

Each step is checked against ``natural_frequencies`` on a model file edited
independently (the TOML document read with tomllib, the value set there,
written back), whoever runs the steps: this process, two local processes, a
dask LocalCluster. Tracking is checked on a crossing with a closed form: the
spring-mass chain's x modes move with the middle spring's x stiffness while its
y and z modes stay at ω² = (4 ∓ √7)/3 k/m.
"""
from __future__ import annotations

import contextlib
import io
import json
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

from linmstmm.cli import main
from linmstmm.determinant import load_kernels
from linmstmm.model import ModelError, load_model
from linmstmm.parameters import get_value, parameter_keys, parse_key, with_values
from linmstmm.solve import natural_frequencies
from linmstmm.sweep import SweepResult, Vary, grid, neighbours, sweep

REPO = Path(__file__).resolve().parents[1]
CHAIN = REPO / "models" / "spring_mass_chain.toml"
MLRS = REPO / "models" / "mlrs" / "mlrs.toml"


# --- an edited model file, written without linmstmm ---------------------------------

def _toml(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(map(_toml, value)) + "]"
    return "inf" if value == math.inf else repr(float(value))


def dump_toml(document: dict) -> str:
    """A model document (tomllib's reading of a model file) as TOML text."""
    lines = [f"{k} = {_toml(v)}" for k, v in document.items() if not isinstance(v, (dict, list))
             or (isinstance(v, list) and not (v and isinstance(v[0], dict)))]
    for key, value in document.items():
        if isinstance(value, dict):
            lines += [f"[{key}]"] + [f"{json.dumps(k)} = {_toml(v)}" for k, v in value.items()]
        elif isinstance(value, list) and value and isinstance(value[0], dict):
            for table in value:
                lines += [f"[[{key}]]"] + [f"{k} = {_toml(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def edited_file(path, edits: dict, folder) -> Path:
    """The model file ``path`` with ``edits`` (key text -> value) set in its TOML document.

    Keys: section.name.field[i] for elements, points.name[i]."""
    document = tomllib.loads(Path(path).read_text())
    for key, value in edits.items():
        head, _, index = key.partition("[")
        section, rest = head.split(".", 1)
        if section == "points":
            document["points"][rest][int(index[:-1])] = value
            continue
        name, field = rest.rsplit(".", 1)
        table = next(t for t in document[section] if t["name"] == name)
        if index:
            table[field][int(index[:-1])] = value
        else:
            table[field] = value
    out = Path(folder) / f"edited_{abs(hash(tuple(edits.items())))}.toml"
    out.write_text(dump_toml(document))
    return out


def reference(path, steps, count, folder, engine) -> np.ndarray:
    """(steps, count) frequencies of ``natural_frequencies`` on each edited file by ``engine``,
    the one the sweep reports it resolved "auto" to (the compiled kernels once another test
    has loaded them: the engines agree to rounding only)."""
    return np.array([natural_frequencies(load_model(edited_file(path, step, folder)), count=count,
                                         engine=engine).frequencies_hz for step in steps])


def run_cli(*argv) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main([str(a) for a in argv])
    return status, out.getvalue(), err.getvalue()


# --- keys ---------------------------------------------------------------------------

def test_every_key_reads_back_the_model_value():
    model = load_model(MLRS)
    keys = parameter_keys(model)
    assert {"rigid.cradle.mass", "spring.tyre1.k[2]", "beam.tube_aft.E", "points.muzzle[0]",
            "rigid.cradle.inertia[0][2]"} <= set(keys)
    assert get_value(model, parse_key(model, "spring.tyre1.k[2]")) == 7.0e6
    assert get_value(model, parse_key(model, "rigid.cradle.inertia[2][0]")) == model.element("cradle").inertia[0, 2]
    for text in keys:
        parse_key(model, text)


@pytest.mark.parametrize("text, hint", [("rigid.cradle.mas", "rigid.cradle.mass"),
                                        ("spring.tyre1.k[6]", "spring.tyre1.k["),
                                        ("beam.tube_aft.e", "beam.tube_aft.E"),
                                        ("points.muzle[0]", "points.muzzle[0]")])
def test_an_unknown_key_is_named_with_the_closest_one(text, hint):
    model = load_model(MLRS)
    with pytest.raises(ModelError) as error:
        parse_key(model, text)
    assert str(error.value).startswith(f"{MLRS}: key '{text}': ")
    assert f"did you mean '{hint}" in str(error.value)


def test_an_edit_changes_that_value_only_and_keeps_the_model_valid():
    model = load_model(MLRS)
    inertia, point = parse_key(model, "rigid.cradle.inertia[0][2]"), parse_key(model, "points.muzzle[2]")
    edited = with_values(model, {inertia: -1400.0, point: 3.5})
    assert edited.element("cradle").inertia[0, 2] == edited.element("cradle").inertia[2, 0] == -1400.0
    beam = edited.element("tube_fore")
    a, b = (edited.points[p] for p in beam.ends)
    assert beam.length == pytest.approx(np.linalg.norm(b - a), rel=1e-15)
    np.testing.assert_allclose(beam.axes[0], (b - a) / beam.length, rtol=0, atol=1e-15)
    assert model.points["muzzle"][2] == 3.470023 and model.element("cradle").inertia[0, 2] != -1400.0
    untouched = [k for k in parameter_keys(model) if not k.startswith(("points.muzzle", "rigid.cradle.inertia"))]
    assert all(get_value(edited, parse_key(edited, k)) == get_value(model, parse_key(model, k)) for k in untouched)


def test_a_step_that_breaks_the_model_names_file_element_key_and_step():
    model = load_model(CHAIN)
    with pytest.raises(ModelError) as error:
        sweep(model, [{"rigid.m2.mass": 2.0}, {"rigid.m2.mass": -1.0}], count=2)
    assert str(error.value) == (f"{CHAIN}: rigid 'm2': key 'mass': mass must be >= 0, got -1 "
                                "(in the step rigid.m2.mass = -1)")


def test_steps_must_set_the_same_keys_and_fill_the_shape():
    model = load_model(CHAIN)
    for steps, shape, message in (([], None, "at least one step"),
                                  ([{"rigid.m2.mass": 1.0}, {"rigid.m1.mass": 1.0}], None, "same keys"),
                                  ([{"rigid.m2.mass": 1.0}], (2,), "does not hold")):
        with pytest.raises(ValueError, match=message):
            sweep(model, steps, shape=shape)


# --- ranges ---------------------------------------------------------------------------

def test_ranges_grid_and_zip():
    assert Vary.parse("beam.b.E=1e9:4e9:4").values().tolist() == [1e9, 2e9, 3e9, 4e9]
    np.testing.assert_allclose(Vary.parse("spring.s.k[0]=10:1000:3:log").values(), [10, 100, 1000], rtol=1e-15)
    a, b = Vary.parse("x=1:2:2"), Vary.parse("y=10:30:3")
    steps, shape = grid([a, b])
    assert shape == (2, 3) and steps[:2] == [{"x": 1.0, "y": 10.0}, {"x": 1.0, "y": 20.0}]
    zipped, shape = grid([Vary.parse("x=1:3:3"), b], zipped=True)
    assert shape == (3,) and zipped[2] == {"x": 3.0, "y": 30.0}
    assert neighbours((2, 3)) == [None, 0, 1, 0, 3, 4]
    for bad in ("x=1:2", "x=1:2:0", "x=0:2:3:log", "x=a:2:3", "=1:2:3"):
        with pytest.raises(ValueError):
            grid([Vary.parse(bad)])
    with pytest.raises(ValueError, match="same N"):
        grid([a, b], zipped=True)


# --- every step is what natural_frequencies gives on the edited file -------------------

def test_chain_grid_equals_freqs_on_the_edited_files(tmp_path):
    steps, shape = grid([Vary.parse("rigid.m2.mass=1.5:3:2"), Vary.parse("spring.k3.k[1]=600:1500:2:log")])
    result = sweep(load_model(CHAIN), steps, count=4, shape=shape)
    np.testing.assert_array_equal(result.frequencies_hz_by_rank, reference(CHAIN, steps, 4, tmp_path, result.engine))
    assert (np.sort(result.frequencies_hz, axis=1) == result.frequencies_hz_by_rank).all()


def test_launcher_equals_freqs_serial_two_processes_and_dask(tmp_path):
    """With the compiled kernels loaded here (as after other tests) "auto" resolves to them
    here, and every runner, in its own processes too, uses them: the same bits."""
    load_kernels()
    steps, _ = grid([Vary.parse("spring.elevation.k[4]=1e7:6e7:3:log"), Vary.parse("beam.tube_aft.E=1.9e11:2.1e11:1")])
    expected = reference(MLRS, steps, 3, tmp_path, "compiled")
    varies = ["--vary", "spring.elevation.k[4]=1e7:6e7:3:log", "--vary", "beam.tube_aft.E=1.9e11:2.1e11:1"]
    outputs = []
    for runner in (["--workers", "1"], ["--workers", "2"], ["--dask", "local"]):
        status, out, err = run_cli("sweep", MLRS, *varies, "--count", 3, "--json", *runner)
        assert status == 0, err
        assert "%|" not in err  # no progress bar on a stderr that is not a terminal
        assert err == "" or runner[0] == "--dask", err  # dask may log what the cluster does
        data = json.loads(out)
        assert data["engine"] == "compiled"
        np.testing.assert_array_equal(data["frequencies_hz_by_rank"], expected)
        assert data["values"] == [list(s.values()) for s in steps]
        outputs.append({k: v for k, v in data.items() if k not in ("seconds", "workers")})
    assert outputs[0] == outputs[1] == outputs[2]


def test_a_moved_point_carries_its_beam_as_the_edited_file_does(tmp_path):
    """The muzzle raised and lowered: the overhanging tube beam takes the new length and axis."""
    steps, shape = grid([Vary.parse("points.muzzle[2]=3.40:3.55:2")])
    result = sweep(load_model(MLRS), steps, count=3, shape=shape)
    np.testing.assert_array_equal(result.frequencies_hz_by_rank, reference(MLRS, steps, 3, tmp_path, result.engine))


def test_a_dask_client_gives_the_serial_result():
    distributed = pytest.importorskip("distributed")
    model = load_model(CHAIN)
    steps, shape = grid([Vary.parse("spring.k2.k[0]=500:2000:3:log")])
    serial = sweep(model, steps, count=3, shape=shape)
    with distributed.LocalCluster(n_workers=2, processes=False, threads_per_worker=1,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        clustered = sweep(model, steps, count=3, shape=shape, dask=client)
    for name in ("frequencies_hz_by_rank", "order", "tracking_mac", "values"):
        np.testing.assert_array_equal(getattr(clustered, name), getattr(serial, name))


# --- tracking ---------------------------------------------------------------------------

def _chain_x(k2):
    """The chain's lowest mode along x with the middle spring's x stiffness ``k2``
    (masses 6 and 2 kg, outer springs 1000 N/m): (Hz, (2,) x of the two masses)."""
    K = np.array([[1000.0 + k2, -k2], [-k2, k2 + 1000.0]])
    values, vectors = scipy.linalg.eigh(K, np.diag([6.0, 2.0]))
    return math.sqrt(values[0]) / (2 * math.pi), vectors[:, 0]


def test_columns_follow_mode_shapes_through_a_crossing():
    """The lowest x mode starts below the (y, z) pair and ends above it: by rank the
    columns swap, tracked the x column keeps the x closed form throughout, and its
    MAC against the step before is that of the closed-form shapes."""
    steps, shape = grid([Vary.parse("spring.k2.k[0]=500:2000:4:log")])
    result = sweep(load_model(CHAIN), steps, count=3, shape=shape)
    unchanged = math.sqrt((4 - math.sqrt(7)) / 3 * 1000 / 2) / (2 * math.pi)
    closed = [_chain_x(step["spring.k2.k[0]"]) for step in steps]
    x = np.array([f for f, _ in closed])
    assert x[0] < unchanged < x[-1]
    np.testing.assert_allclose(result.frequencies_hz[:, 0], x, rtol=1e-12)
    np.testing.assert_allclose(result.frequencies_hz[:, 1:], unchanged, rtol=1e-12)
    assert result.order[0].tolist() == [0, 1, 2] and result.order[-1, 0] == 2
    assert np.sort(result.frequencies_hz_by_rank[-1]).tolist() == result.frequencies_hz_by_rank[-1].tolist()
    shapes = np.array([u for _, u in closed])
    mac = (np.sum(shapes[1:] * shapes[:-1], axis=1) ** 2
           / (np.sum(shapes[1:] ** 2, axis=1) * np.sum(shapes[:-1] ** 2, axis=1)))
    np.testing.assert_allclose(result.tracking_mac[1:, 0], mac, rtol=1e-9)
    np.testing.assert_allclose(result.tracking_mac[:, 1:], 1.0, rtol=1e-9)


def test_repeated_frequencies_keep_their_multiplicity():
    result = sweep(load_model(CHAIN), [{"rigid.m2.mass": 2.0}], count=6)
    slow, fast = (math.sqrt((4 + s * math.sqrt(7)) / 3 * 1000 / 2) / (2 * math.pi) for s in (-1, 1))
    np.testing.assert_allclose(result.frequencies_hz_by_rank[0], [slow] * 3 + [fast] * 3, rtol=1e-12)


# --- command line ------------------------------------------------------------------------

def test_cli_csv_plot_and_table(tmp_path):
    csv_file, png = tmp_path / "sweep.csv", tmp_path / "sweep.png"
    status, out, err = run_cli("sweep", CHAIN, "--vary", "spring.k2.k[0]=500:2000:3:log", "--count", 3,
                               "--csv", csv_file, "--plot", png, "--quiet")
    assert status == 0, err
    assert err == "" and "mode 1 [Hz]" in out
    header, *rows = csv_file.read_text().splitlines()
    assert header.split(",")[:2] == ["spring.k2.k[0] [N/m]", "mode 1 [Hz]"] and len(rows) == 3
    assert header.split(",")[-1] == "mode 3 MAC" and "wrote" in out
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_cli_output_writes_the_json_it_prints(tmp_path):
    argv = ["sweep", CHAIN, "--vary", "rigid.m2.mass=1:3:2", "--count", 2, "--sensitivity"]
    status, out, err = run_cli(*argv, "--output", tmp_path / "s.json", "--csv", tmp_path / "s.csv")
    assert status == 0 and "wrote" in out, err
    saved = json.loads((tmp_path / "s.json").read_text())
    status, out, _ = run_cli(*argv, "--json")
    printed = json.loads(out)
    assert {k: v for k, v in saved.items() if k not in ("seconds",)} == \
        {k: v for k, v in printed.items() if k not in ("seconds",)}
    header = (tmp_path / "s.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "rigid.m2.mass [kg]" and header[-1] == "dmode 2/drigid.m2.mass [Hz/kg]"


@pytest.mark.parametrize("argv, message", [
    (["--vary", "rigid.m2.mas=1:2:2"], "key 'rigid.m2.mas': names no number of the model (did you mean 'rigid.m2.mass'?)"),
    (["--vary", "rigid.m2.mass=1:2"], "is not KEY=START:STOP:N"),
    (["--vary", "rigid.m2.mass=1:2:2", "--vary", "spring.k1.k[0]=1:2:3", "--zip"], "same N"),
    (["--vary", "rigid.m2.mass=-1:2:2"], "mass must be >= 0, got -1 (in the step rigid.m2.mass = -1)"),
])
def test_cli_bad_requests_exit_2_with_one_line(argv, message):
    status, out, err = run_cli("sweep", CHAIN, *argv)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and message in err and "Traceback" not in err


def test_compiled_engine_and_warm_starts_give_freqs_to_rounding_whoever_runs_the_steps(tmp_path):
    """--engine compiled --warm-start: every step started from its neighbour's roots, det
    by the kernels in every process. Serial and two processes give the same bits (each
    step starts from the same neighbour), and both what freqs gives on the edited files
    from a cold start with numpy, to rounding."""
    varies = ["--vary", "rigid.m2.mass=1.5:3:3", "--vary", "spring.k3.k[1]=600:1500:3:log"]
    steps, _ = grid([Vary.parse(varies[1]), Vary.parse(varies[3])])
    outputs = []
    for runner in (["--workers", "1"], ["--workers", "2"]):
        status, out, err = run_cli("sweep", CHAIN, *varies, "--count", 4, "--json", "--engine", "compiled",
                                   "--warm-start", *runner)
        assert status == 0, err
        outputs.append(json.loads(out))
    assert outputs[0]["engine"] == "compiled" and outputs[0]["warm_start"] is True
    assert {k: v for k, v in outputs[0].items() if k not in ("seconds", "workers")} == \
        {k: v for k, v in outputs[1].items() if k not in ("seconds", "workers")}
    np.testing.assert_allclose(outputs[0]["frequencies_hz_by_rank"], reference(CHAIN, steps, 4, tmp_path, "numpy"),
                               rtol=1e-12)
    loaded = SweepResult.from_dict(outputs[0])  # how it ran is kept too
    assert (loaded.engine, loaded.warm_start) == ("compiled", True)


def test_a_study_without_tracking_gives_the_same_frequencies_by_rank():
    """track_modes=False skips the mode shapes (natural_frequencies per step): the same
    roots, bit for bit, each column its rank; sensitivities are refused without shapes."""
    chain = load_model(CHAIN)
    steps = grid([Vary("spring.k2.k[0]", 500.0, 2000.0, 4, log=True)])[0]
    tracked = sweep(chain, steps, count=3)
    by_rank = sweep(chain, steps, count=3, track_modes=False)
    assert np.array_equal(by_rank.frequencies_hz_by_rank, tracked.frequencies_hz_by_rank)
    assert np.array_equal(by_rank.order, np.tile(np.arange(3), (4, 1)))
    assert np.all(np.isnan(by_rank.tracking_mac))
    with pytest.raises(ValueError, match="track_modes"):
        sweep(chain, steps, count=3, sensitivity=True, track_modes=False)


def test_a_column_whose_mode_leaves_the_lowest_count_is_marked(tmp_path):
    """The chain's x-mode rises with spring k2's x stiffness and leaves the lowest 4 at
    1149 N/m; a y/z mode (MAC 0 with it: another direction) takes its column there.
    The table marks that cell and says why; the CSV carries each column's MAC."""
    argv = ("sweep", CHAIN, "--vary", "spring.k2.k[0]=500:2000:6:log", "--count", 4, "--quiet")
    status, out, _ = run_cli(*argv)
    assert status == 0
    rows = [line for line in out.splitlines() if line.strip()[:1].isdigit()]
    marked = [(i, cell) for i, line in enumerate(rows) for cell in line.split() if cell.endswith("*")]
    assert len(marked) == 1 and marked[0][0] == 3
    assert "another mode than the step before" in out
    status, _, _ = run_cli(*argv, "--csv", tmp_path / "sweep.csv")
    header, *lines = (tmp_path / "sweep.csv").read_text().splitlines()
    column = header.split(",").index("mode 4 MAC")
    assert [float(line.split(",")[column]) < 0.5 for line in lines] == [False, False, False, True, False, False]


def test_a_step_starts_from_its_neighbour_unless_the_last_move_outran_the_predictions():
    """A neighbour's roots start the next step while the last move seen between
    neighbours is within the square root of the coarse predictions' error (half their
    digits), or either is not known yet; beyond it the step starts cold."""
    from linmstmm.sweep import StepSolution
    from linmstmm.warm_starts import warm_starts

    roots = np.array([3.0, 4.0])

    def neighbour(moved, error):
        return StepSolution(roots, 0, np.zeros((2, 0, 6)), moved=moved, prediction_error=error)

    assert warm_starts(None) is None
    for moved, error in ((math.nan, 1e-6), (1e-2, math.nan), (math.nan, math.nan), (9e-4, 1e-6)):
        assert warm_starts(neighbour(moved, error)) is roots
    assert warm_starts(neighbour(1.1e-3, 1e-6)) is None
    assert warm_starts(neighbour(1e-2, 1e-3)) is roots and warm_starts(neighbour(4e-2, 1e-3)) is None


def test_a_step_starts_from_its_neighbours_trend_where_that_missed_less_than_the_roots_moved():
    """Where the neighbour's own start is known, its roots extrapolated along their last
    move (2 f - f_before, rank by rank) start the step, provided the same extrapolation
    missed the neighbour's roots by less than they moved and by no more than the square
    root of the predictions' error, and the move is smaller than the closest relative
    gap between the neighbour's roots (a veering pair may swap ranks within one move)."""
    from linmstmm.sweep import StepSolution
    from linmstmm.warm_starts import trend, warm_starts

    roots, before = np.array([3.0, 4.0]), np.array([2.97, 3.96])

    def neighbour(moved, missed, error=1e-6, found=roots):
        return StepSolution(found, 0, np.zeros((2, 0, 6)), moved=moved, previous_hz=before,
                            trend_miss=missed, prediction_error=error)

    np.testing.assert_allclose(trend(neighbour(1e-2, 1e-4)), [3.03, 4.04])
    np.testing.assert_allclose(warm_starts(neighbour(1e-2, 1e-4)), [3.03, 4.04])
    assert warm_starts(neighbour(1e-2, 1.1e-3)) is None  # missed by more than √1e-6
    assert warm_starts(neighbour(5e-4, 6e-4)) is roots  # the roots moved less than the trend missed
    assert warm_starts(neighbour(1e-2, math.nan)) is None  # no miss measured: the old rule
    assert warm_starts(neighbour(3e-2, 1e-4, found=np.array([3.0, 3.06]))) is None  # gap 2 % < move 3 %
    assert trend(StepSolution(roots, 0, np.zeros((2, 0, 6)))) is None  # no step before
    assert trend(neighbour(0.7, 1e-4, found=np.array([1.0, 4.0]))) is None  # 2 - 2.97 < 0
