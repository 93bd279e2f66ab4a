"""The result classes on one base (linmstmm.results.Result).

Every result class, built by a real solve of a bundled model: save -> load
and from_dict(to_record()) give an object equal field by field (arrays of
the same dtype, shape and bits, complex ones included); the saved file keeps
the command line's object unchanged; load refuses a file of another kind or
no result at all with a ModelError naming the file and key; plot() returns a
matplotlib Figure of the result's own numbers, and matplotlib is imported by
plot() only.
"""
from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
from matplotlib.figure import Figure  # noqa: E402

import linmstmm as lm  # noqa: E402
from linmstmm.response import step  # noqa: E402
from linmstmm.results import Result, decode_array, encode_array  # noqa: E402
from linmstmm.studies import ScanResult, determinant_scan  # noqa: E402
from linmstmm.sweep import SweepResult, Vary, grid, sweep  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"


def same(a, b, where="result") -> None:
    """Assert ``a`` and ``b`` equal: dataclasses field by field, arrays by dtype, shape and
    values (NaN equal to NaN), dicts by keys in order, sequences by type and items."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} != {type(b).__name__}"
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype, f"{where}: dtype {a.dtype} != {b.dtype}"
        assert a.shape == b.shape, f"{where}: shape {a.shape} != {b.shape}"
        assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), f"{where}: values differ"
    elif isinstance(a, dict):
        assert list(a) == list(b), f"{where}: keys {list(a)} != {list(b)}"
        for key in a:
            same(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), f"{where}: length {len(a)} != {len(b)}"
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{where}[{i}]")
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


def test_same_sees_dtype_shape_value_and_type_differences():
    same(np.arange(3.0), np.arange(3.0))
    for a, b in [(np.arange(3.0), np.arange(3)), (np.zeros((2, 3)), np.zeros((3, 2))),
                 (np.arange(3.0), np.arange(3.0) + 1e-16 * 3), (("a",), ["a"]), ({"a": 1, "b": 2}, {"b": 2, "a": 1})]:
        with pytest.raises(AssertionError):
            same(a, b)


# --- results of real solves ---------------------------------------------------------

@pytest.fixture(scope="module")
def cantilever():
    return lm.load_model(MODELS / "cantilever_tip_mass.toml")


@pytest.fixture(scope="module")
def cantilever_modes(cantilever):
    return lm.mode_shapes(cantilever, count=4)


def _launcher_frequencies(_):
    return lm.natural_frequencies(lm.load_model(MODELS / "mlrs" / "mlrs.toml"), count=4)


def _mpmath_frequencies(models):
    return lm.natural_frequencies(models["cantilever"], count=2, digits=20)


def _modes(models):
    return models["modes"]


def _fe(models):
    return lm.fe_frequencies(models["cantilever"], count=3, mode_shapes=True)


def _damped(_):
    return lm.damped_frequencies(lm.load_model(MODELS / "dashpot_chain.toml"), count=6)


def _response(models):
    load = lm.PointLoad("tip", force=np.array([0.0, 0.0, -100.0]), moment=np.zeros(3), time=step(0.0))
    return lm.modal_response(models["modes"], [load], np.linspace(0.0, 0.15, 7), points=["tip", "root"],
                             damping=(0.0, 1e-3))


def _frf(models):
    return lm.frf(models["modes"], "tip", [0.0, 0.0, 1.0, 0.0, 0.0, 0.0], np.linspace(1.0, 20.0, 5),
                  damping=(0.0, 1e-3))


def _sweep(_):
    model = lm.load_model(MODELS / "spring_mass_chain.toml")
    steps, shape = grid([Vary.parse("spring.k2.k[0]=500:2000:3:log"), Vary.parse("rigid.m1.mass=5:7:2")])
    return sweep(model, steps, count=3, shape=shape, sensitivity=True)


def _scan(models):
    return determinant_scan(models["cantilever"], fmax=60.0, points=200)


#: name -> (result class, builder from the shared models)
BUILDS = {
    "launcher frequencies": (lm.FrequencyResult, _launcher_frequencies),
    "frequencies in mpmath": (lm.FrequencyResult, _mpmath_frequencies),
    "modes": (lm.ModalResult, _modes),
    "fe": (lm.FEResult, _fe),
    "damped": (lm.DampedResult, _damped),
    "response": (lm.ResponseResult, _response),
    "frf": (lm.FRFResult, _frf),
    "sweep": (SweepResult, _sweep),
    "scan": (ScanResult, _scan),
}
#: The classes whose to_dict (the command line's object) holds everything.
COMPLETE_DICT = {lm.FrequencyResult, lm.DampedResult, lm.FRFResult, SweepResult}


@pytest.fixture(scope="module")
def results(cantilever, cantilever_modes):
    models = {"cantilever": cantilever, "modes": cantilever_modes}
    return {name: build(models) for name, (_, build) in BUILDS.items()}


def test_every_result_class_derives_from_the_base_with_its_own_kind():
    classes = {cls for cls, _ in BUILDS.values()}
    assert all(issubclass(cls, lm.Result) for cls in classes)
    assert len({cls.kind for cls in classes}) == len(classes) == 8
    assert lm.Result is Result


@pytest.mark.parametrize("name", BUILDS)
def test_save_and_load_give_an_equal_result(results, name, tmp_path):
    result, cls = results[name], BUILDS[name][0]
    assert type(result) is cls
    path = tmp_path / "result.json"
    result.save(path)
    record = json.loads(path.read_text())
    assert record["kind"] == cls.kind and record["version"] == lm.__version__
    # the command line's object is in the file unchanged (to_dict holds no numpy types)
    assert {key: record["result"][key] for key in result.to_dict()} == json.loads(json.dumps(result.to_dict()))
    same(cls.load(path), result)
    same(cls.from_dict(result.to_record()), result)


def test_the_results_hold_what_the_round_trips_must_keep(results):
    assert results["frequencies in mpmath"].frequencies_text is not None
    assert np.iscomplexobj(results["frf"].receptance) and np.abs(results["frf"].receptance.imag).max() > 0
    assert np.iscomplexobj(results["damped"].roots) and np.abs(results["damped"].roots.real).max() > 0
    assert results["fe"].mode_shapes is not None and results["fe"].mode_shapes.ndim == 2
    assert results["modes"].port_states and results["modes"].boundary_unknowns.size
    assert results["sweep"].sensitivities and results["sweep"].order.dtype.kind == "i"
    assert len(results["sweep"].shape) == 2 and np.isnan(results["sweep"].frequencies_hz_by_rank).sum() == 0
    assert results["scan"].roots.size == 4 and results["scan"].omega.size == 200


@pytest.mark.parametrize("name", BUILDS)
def test_from_dict_of_to_dict(results, name):
    """Where to_dict holds everything it rebuilds the result; elsewhere the missing key is named."""
    result, cls = results[name], BUILDS[name][0]
    if cls in COMPLETE_DICT:
        same(cls.from_dict(result.to_dict()), result)
        return
    with pytest.raises(lm.ModelError) as error:
        cls.from_dict(result.to_dict())
    assert error.value.key in result.to_record() and error.value.key not in result.to_dict()
    assert cls.__name__ in str(error.value)


@pytest.mark.parametrize("name", ["launcher frequencies", "modes", "fe", "damped", "response", "frf", "sweep", "scan"])
def test_load_refuses_a_file_of_another_kind(results, name, tmp_path):
    result = results[name]
    path = tmp_path / "result.json"
    result.save(path)
    for other in {cls for cls, _ in BUILDS.values()} - {type(result)}:
        with pytest.raises(lm.ModelError) as error:
            other.load(path)
        assert error.value.key == "kind" and error.value.file == str(path)
        assert f"{type(result).__name__}.load reads it" in str(error.value)


@pytest.mark.parametrize("name", BUILDS)
def test_the_base_class_loads_every_kind(results, name, tmp_path):
    """``Result.load`` reads a file of any kind as the class that wrote it."""
    result = results[name]
    path = tmp_path / "result.json"
    result.save(path)
    again = Result.load(path)
    assert type(again) is type(result)
    same(again, result)


def test_the_base_class_loads_a_kind_whose_module_is_not_imported_yet(tmp_path):
    """In a new process ``Result.load`` imports the module of the kind it meets (here the FE route's)."""
    path = tmp_path / "fe.json"
    lm.fe_frequencies(lm.load_model(MODELS / "spring_mass_chain.toml"), count=2).save(path)
    script = f"""
import sys
from linmstmm.results import Result
print("linmstmm.fe.result" in sys.modules, type(Result.load({str(path)!r})).__name__)
"""
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True,
                            cwd=ROOT).stdout.split()
    assert output == ["False", "FEResult"]


def test_the_base_class_refuses_an_unknown_kind(tmp_path):
    path = tmp_path / "result.json"
    path.write_text(json.dumps({"kind": "nonsense", "version": lm.__version__, "result": {}}))
    with pytest.raises(lm.ModelError, match="unknown kind 'nonsense'") as error:
        Result.load(path)
    assert error.value.key == "kind"


@pytest.mark.parametrize("text", ["not json {", '{"frequencies_hz": [1.0]}', "[1, 2]"])
def test_load_refuses_what_is_not_a_saved_result(tmp_path, text):
    path = tmp_path / "other.json"
    path.write_text(text)
    with pytest.raises(lm.ModelError) as error:
        lm.FrequencyResult.load(path)
    assert str(error.value).startswith(str(path))


def test_load_names_a_missing_key(results, tmp_path):
    path = tmp_path / "result.json"
    results["modes"].save(path)
    record = json.loads(path.read_text())
    del record["result"]["port_states"]
    path.write_text(json.dumps(record))
    with pytest.raises(lm.ModelError) as error:
        lm.ModalResult.load(path)
    assert (error.value.file, error.value.key) == (str(path), "port_states")


def test_complex_arrays_survive_json():
    values = np.random.default_rng(1).standard_normal((2, 3, 4)) * (1 + 1j) + 1j * np.pi
    back = decode_array(json.loads(json.dumps(encode_array(values))), ndim=3)
    same(back, values)
    same(decode_array([], ndim=2), np.empty((0, 0)))


# --- figures ------------------------------------------------------------------------

def _plot(result, cantilever):
    return result.plot(model=cantilever) if isinstance(result, lm.ModalResult) else result.plot()


@pytest.mark.parametrize("name", BUILDS)
def test_plot_returns_a_figure(results, cantilever, name):
    figure = _plot(results[name], cantilever)
    assert isinstance(figure, Figure) and figure.axes
    figure.canvas.draw()  # draws without error


def test_the_figures_draw_the_results_numbers(results, cantilever):
    frequencies = results["launcher frequencies"]
    line, = frequencies.plot().axes[0].get_lines()
    assert np.array_equal(line.get_ydata(), frequencies.frequencies_hz)
    fe = results["fe"]
    top, bottom = fe.plot().axes
    assert np.array_equal(top.get_lines()[0].get_ydata(), fe.frequencies_hz)
    assert np.array_equal(bottom.get_lines()[0].get_ydata(), fe.error_estimate)
    damped = results["damped"]
    points = [line for line in damped.plot().axes[0].get_lines() if line.get_marker() == "o"]
    assert np.array_equal(points[0].get_ydata(), damped.damping_ratio)
    modes = results["modes"]
    assert f"{modes.frequencies_hz[1]:.6g} Hz" in modes.plot(cantilever, mode=1)._suptitle.get_text()
    swept = results["sweep"]
    lines = swept.plot().axes[0].get_lines()
    assert len(lines) == swept.frequencies_hz.shape[1] * 2  # a line per mode and per value of the second key
    scan = results["scan"]
    count, = [line for line in scan.plot().axes[1].get_lines() if line.get_drawstyle() == "steps-post"]
    assert np.array_equal(count.get_ydata(), scan.count())


def test_matplotlib_is_imported_by_plot_only(tmp_path):
    script = f"""
import sys
import linmstmm as lm
model = lm.load_model({str(MODELS / "cantilever_tip_mass.toml")!r})
result = lm.natural_frequencies(model, count=2)
modes = lm.mode_shapes(model, count=2)
result.save({str(tmp_path / "f.json")!r})
lm.FrequencyResult.load({str(tmp_path / "f.json")!r}).to_dict()
modes.to_record()
print("matplotlib" in sys.modules)
result.plot()
print("matplotlib" in sys.modules)
"""
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True,
                            cwd=ROOT).stdout.split()
    assert output == ["False", "True"]
