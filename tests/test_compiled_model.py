"""A model compiled once for the root search (linmstmm.compiled_model): a second solve of
the same model object reuses what does not depend on ω, and finds the same roots
with the same work, nothing found before carried over."""
from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

from linmstmm.builders import fixed, single_beam_model, spring_chain
from linmstmm.fe import fe_frequencies
from linmstmm.compiled_model import compiled_system, forget_compiled_models
from linmstmm.model import load_model
from linmstmm.solve import frequency_finder, natural_frequencies


def test_a_second_solve_reuses_the_compilation_and_repeats_the_work():
    model = load_model("models/mlrs/mlrs.toml")
    forget_compiled_models()
    first = natural_frequencies(model, count=10, engine="compiled")
    system = compiled_system(model, engine="compiled")
    second = natural_frequencies(model, count=10, engine="compiled")
    assert compiled_system(model, engine="compiled") is system
    assert np.array_equal(first.frequencies_hz, second.frequencies_hz)
    assert second.evaluations == first.evaluations > 0  # evaluated afresh, not remembered


def test_each_finder_counts_afresh():
    model = load_model("models/mlrs/mlrs.toml")
    _, finder, _ = frequency_finder(model, engine="compiled")
    omega = 2 * np.pi * 3.0
    finder.counter(omega)
    _, other, _ = frequency_finder(model, engine="compiled")
    assert other.counter is not finder.counter and omega not in other.counter._answers
    assert other.counter(omega) == finder.counter(omega)


def test_a_new_model_object_or_forgetting_compiles_anew():
    model = single_beam_model()
    system = compiled_system(model, engine="numpy")
    assert compiled_system(single_beam_model(), engine="numpy") is not system
    assert compiled_system(model, engine="compiled") is not system   # another engine, another program
    forget_compiled_models()
    assert compiled_system(model, engine="numpy") is not system


def test_the_rigid_body_zeros_are_divided_out_on_every_solve():
    """A free beam's six rigid-body zeros: confirmed once, divided out of each new finder,
    and the frequencies those finders find agree with the closed form."""
    model = single_beam_model(Iy=2e-7, Iz=5e-7, axial=False, torsion=False)
    forget_compiled_models()
    assert compiled_system(model).rigid_zeros_confirmed
    finders = [frequency_finder(model)[1] for _ in range(2)]
    assert all(finder._divided for finder in finders)
    beam = model.beams[0]
    lam = 4.730040744862704  # free-free: cos λ cosh λ = 1
    lowest = (lam / beam.length) ** 2 * np.sqrt(beam.E * 2e-7 / (beam.rho * beam.A))
    for _ in range(2):
        result = natural_frequencies(model, count=1)
        assert result.rigid_body_modes == 6
        assert abs(2 * np.pi * result.frequencies_hz[0] / lowest - 1) < 1e-12


def test_auto_leaves_a_long_chain_to_the_numpy_carry_that_powers_its_cells():
    """With the kernels loaded, "auto" compiles the launcher but not a 300-body chain of
    equal cells (its runs the numpy carry multiplies by powers of the cell matrix;
    compiled, a 10,000-body chain took 16 s instead of 0.5 s); its frequencies are
    the closed form's either way."""
    from linmstmm.determinant import CompiledDeterminant, NumpyDeterminant, load_kernels

    load_kernels()
    n, k, m = 300, 1e6, 1.0
    chain = spring_chain(n, m, k)
    assert isinstance(compiled_system(chain).determinant, NumpyDeterminant)
    launcher = load_model("models/mlrs/mlrs.toml")
    assert isinstance(compiled_system(launcher).determinant, CompiledDeterminant)
    lowest = 2 * np.sqrt(k / m) * np.sin(np.pi / (2 * (2 * n + 1)))
    result = natural_frequencies(chain, count=3)
    assert np.allclose(2 * np.pi * result.frequencies_hz, lowest, rtol=1e-9)


def test_kernels_pay_for_a_large_request_carried_element_by_element():
    """"auto" loads the kernels (compiled here already) where the elements carried one at a
    time (a beam weighs BEAM_WEIGHT) times the frequencies asked for reach KERNELS_PAY_FROM:
    not for the launchers' ten lowest, nor for a long chain of equal cells (powered by the
    numpy carry) however many, but for a cantilever and a chain of unequal bodies, the
    sooner the more frequencies are asked for."""
    from builders import cantilever_of_beams, unequal_chain
    from linmstmm.deduction import Deduction
    from linmstmm.determinant import BEAM_WEIGHT, KERNELS_PAY_FROM, kernels_compiled, kernels_pay
    from linmstmm.topology import build_topology

    natural_frequencies(load_model("models/mlrs/mlrs.toml"), 1, engine="compiled")  # compiled here, cached
    assert kernels_compiled()

    def pays(model, frequencies):
        return kernels_pay(Deduction(build_topology(model)), frequencies)

    for launcher in ("models/mlrs/mlrs.toml", "models/launcher2/launcher2.toml"):
        assert not pays(load_model(launcher), 10) and not pays(load_model(launcher), 100)
    assert not pays(spring_chain(3000), 100)  # equal cells: the numpy carry powers them
    for frequencies in (10, 20, 40):
        beams = -(-KERNELS_PAY_FROM // (BEAM_WEIGHT * frequencies))  # the fewest beams that weigh that much
        assert not pays(cantilever_of_beams(beams - 1), frequencies) and pays(cantilever_of_beams(beams), frequencies)
        bodies = -(-KERNELS_PAY_FROM // (2 * frequencies))  # a body and a spring each
        assert not pays(unequal_chain(bodies - 1), frequencies) and pays(unequal_chain(bodies), frequencies)


def test_kernels_pay_for_a_sweep_of_a_small_model_long_enough():
    """A sweep's steps count together: the launcher (30 elements, two of them beams) pays
    for the kernels from the step where its weight times the frequencies times the steps
    reaches KERNELS_PAY_FROM."""
    from linmstmm.deduction import Deduction
    from linmstmm.determinant import BEAM_WEIGHT, KERNELS_PAY_FROM, carried_weight, kernels_pay
    from linmstmm.topology import build_topology

    natural_frequencies(load_model("models/mlrs/mlrs.toml"), 1, engine="compiled")  # compiled here, cached
    deduction = Deduction(build_topology(load_model("models/mlrs/mlrs.toml")))
    weight = carried_weight(deduction.topology)
    assert weight == 28 + 2 * BEAM_WEIGHT
    steps = -(-KERNELS_PAY_FROM // (weight * 5))
    assert not kernels_pay(deduction, 5, steps - 1) and kernels_pay(deduction, 5, steps)
    equal_cells = Deduction(build_topology(spring_chain(3000)))  # powered by the numpy carry, however often
    assert not kernels_pay(equal_cells, 5, 1000)


def test_auto_loads_the_kernels_for_a_large_model_in_a_new_process():
    """In a new process "auto" solves a launcher by the numpy carry; a 500-element
    cantilever's six lowest too, polished from predictions without a counter (3 · 500 ·
    (6 + PREDICTED_FIXED) = 24,000 is below PREDICTED_PAY_FROM), and so a round one's,
    whose double roots are polished from their predictions too (1.10-1.18 s in a new
    process by numpy, 0.92-1.11 s by the kernels); but its twenty lowest (45,000) by the
    kernels (compiled on this machine) it loads for them; a sweep's steps follow
    KERNELS_PAY_FROM; the frequencies are numpy's to rounding."""
    import subprocess
    import sys

    from linmstmm.determinant import BEAM_WEIGHT, KERNELS_PAY_FROM, PREDICTED_FIXED, PREDICTED_PAY_FROM

    weight = BEAM_WEIGHT * 500
    assert weight * 6 >= KERNELS_PAY_FROM
    assert weight * (6 + PREDICTED_FIXED) < PREDICTED_PAY_FROM <= weight * (20 + PREDICTED_FIXED)
    natural_frequencies(load_model("models/mlrs/mlrs.toml"), 1, engine="compiled")  # compiled here, cached

    prelude = (f"import sys, dataclasses, numpy as np; sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
               "from builders import cantilever_of_beams\n"
               "from linmstmm import load_model, natural_frequencies\n"
               "from linmstmm.determinant import kernels_loaded\n"
               "from linmstmm.sweep import _step_engine\n"
               "def rounded(model):\n"
               "    return dataclasses.replace(model, beams=tuple(dataclasses.replace(b, Iz=b.Iy) for b in model.beams))\n")
    code = (prelude
            + "natural_frequencies(load_model('models/mlrs/mlrs.toml'), 10); print(kernels_loaded())\n"
            "print(_step_engine(load_model('models/mlrs/mlrs.toml'), 'auto', 5, 1), "
            "_step_engine(load_model('models/mlrs/mlrs.toml'), 'auto', 5, 1000), "
            "_step_engine(cantilever_of_beams(500), 'auto', 6, 1))\n"
            "six = natural_frequencies(cantilever_of_beams(500), 6); print(six.engine)\n"
            "print(natural_frequencies(rounded(cantilever_of_beams(500)), 6).engine)\n"
            "auto = natural_frequencies(cantilever_of_beams(500), 20); print(auto.engine)\n"
            "plain = natural_frequencies(cantilever_of_beams(500), 20, engine='numpy')\n"
            "print(np.abs(auto.frequencies_hz / plain.frequencies_hz - 1).max())\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    launcher, sweep_launcher, long_sweep_launcher, sweep_cantilever, six, round_six, twenty, difference = (
        run.stdout.split())
    assert (launcher, six, round_six, twenty) == ("False", "numpy", "numpy", "compiled")
    # a sweep's steps follow KERNELS_PAY_FROM, counted together
    assert (sweep_launcher, long_sweep_launcher, sweep_cantilever) == ("numpy", "compiled", "compiled")
    assert float(difference) < 1e-12


def test_a_model_built_in_code_cannot_be_changed_under_its_compiled_solve():
    """A model solved once is answered for from its compilation, so it must not change in
    place: its boundary and points (dicts) and the arrays its records were built from
    are refused, and a clamped-free beam stays one (10.2 Hz where the FE route gives
    65.1 Hz for a clamped-clamped beam was the stale answer of a boundary changed in place)."""
    position = np.array([2.0, 0.0, 0.0])
    beam = single_beam_model(fixed(), None)
    free_end = next(p for p in beam.points if p not in beam.boundary)
    before = natural_frequencies(beam, 4).frequencies_hz
    with pytest.raises(TypeError, match="cannot be changed in place"):
        beam.boundary[free_end] = fixed()
    with pytest.raises(TypeError, match="cannot be changed in place"):
        beam.points.update({free_end: position})
    with pytest.raises(ValueError, match="read-only"):
        beam.points[free_end][0] = 3.0
    with pytest.raises(ValueError, match="read-only"):
        beam.beams[0].axes[0, 0] = -1.0
    forget_compiled_models()
    np.testing.assert_array_equal(natural_frequencies(beam, 4).frequencies_hz, before)
    fe = fe_frequencies(beam, count=4)
    np.testing.assert_allclose(before, fe.frequencies_hz, rtol=max(1e-9, 3 * float(np.max(fe.error_estimate))))


def test_a_frozen_model_pickles_and_compares_as_its_dicts():
    beam = single_beam_model(fixed(), None)
    copy = pickle.loads(pickle.dumps(beam))
    assert dict(copy.boundary).keys() == dict(beam.boundary).keys()
    assert all(np.array_equal(copy.points[p], beam.points[p]) for p in beam.points)
    np.testing.assert_array_equal(natural_frequencies(copy, 3).frequencies_hz,
                                  natural_frequencies(beam, 3).frequencies_hz)


def test_two_threads_solving_one_model_each_report_their_own_work():
    """The compiled model's determinant serves both searches: each result's evaluations
    are those one solve alone takes (counted across both threads, 106 to 216 where
    one solve takes 86 on the launcher) and its frequencies the same bits."""
    import threading

    model = load_model("models/mlrs/mlrs.toml")
    alone = natural_frequencies(model, count=20, engine="compiled")
    results = {0: [], 1: []}

    def solve(thread: int) -> None:
        results[thread] += [natural_frequencies(model, count=20, engine="compiled") for _ in range(6)]

    threads = [threading.Thread(target=solve, args=(t,)) for t in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for result in results[0] + results[1]:
        assert result.evaluations == alone.evaluations > 0
        np.testing.assert_array_equal(result.frequencies_hz, alone.frequencies_hz)


def test_results_say_which_engine_evaluated():
    """A frequency and a modal result name the engine that evaluated det Ū_all, and keep
    it through their dictionaries; the command's JSON and table carry it."""
    import contextlib
    import io
    import json

    from linmstmm.cli import main
    from linmstmm.modes import ModalResult, mode_shapes
    from linmstmm.solve import FrequencyResult

    model = load_model("models/cantilever_tip_mass.toml")
    for engine in ("numpy", "compiled"):
        frequencies = natural_frequencies(model, 2, engine=engine)
        modes = mode_shapes(model, 2, engine=engine)
        assert frequencies.engine == modes.engine == engine
        assert FrequencyResult.from_dict(frequencies.to_dict()).engine == engine
        assert ModalResult.from_dict(modes.to_record()).engine == engine
    for extra in (["--json"], []):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            assert main(["freqs", "models/cantilever_tip_mass.toml", "--count", "2", "--engine", "compiled",
                         *extra]) == 0
        text = out.getvalue()
        if extra:
            assert json.loads(text)["engine"] == "compiled"
        else:
            assert "solve time" in text and "(compiled engine)" in text


def test_a_sweeps_auto_follows_a_solves_auto_and_counts_steps_per_process(monkeypatch):
    """With the kernels loaded here a sweep's "auto" is what a solve's would be: the kernels
    for the launcher, numpy for a chain of equal cells (which the numpy carry powers); and
    the steps it counts are those each process runs."""
    import linmstmm.sweep as sweep_module
    from linmstmm.sweep import Vary, grid

    natural_frequencies(load_model("models/mlrs/mlrs.toml"), 1, engine="compiled")  # loaded here
    assert sweep_module._step_engine(load_model("models/mlrs/mlrs.toml"), "auto", 5, 1) == "compiled"
    assert sweep_module._step_engine(spring_chain(3000), "auto", 5, 1) == "numpy"
    assert sweep_module._step_engine(spring_chain(3000), "compiled", 5, 1) == "compiled"

    asked = []
    monkeypatch.setattr(sweep_module, "_step_engine",
                        lambda model, engine, count, steps: asked.append(steps) or "numpy")
    steps, shape = grid([Vary.parse("spring.k2.k[0]=500:2000:5:log")])
    for workers in (1, 2):
        sweep_module.sweep(load_model("models/spring_mass_chain.toml"), steps, count=2, shape=shape,
                           workers=workers, track_modes=False)
    assert asked == [5, 3]


def test_deciding_the_engine_builds_a_large_models_topology_once(monkeypatch):
    """Where the model's size leaves the kernels possible, "auto" decides on a topology it
    builds once per model object and hands to the system's build: a long chain of equal
    cells (never the kernels) solved three times builds its topology once (each solve
    building it again cost a 10,000-body chain 0.15 s a solve)."""
    import linmstmm.compiled_model as compiled_model_module

    forget_compiled_models()
    monkeypatch.setattr(compiled_model_module, "kernels_loaded", lambda: False)  # as in a new process
    built = []
    original = compiled_model_module.build_topology
    monkeypatch.setattr(compiled_model_module, "build_topology",
                        lambda *args, **kwargs: built.append(1) or original(*args, **kwargs))
    chain = spring_chain(3000)
    for count in (10, 20, 40):
        natural_frequencies(chain, count, engine="auto")
    assert len(built) == 1


def test_a_result_saved_before_results_recorded_their_engine_still_loads():
    """A frequency or modal result written before the engine was recorded loads, and says
    its engine is unrecorded rather than guessing one."""
    from linmstmm.modes import ModalResult, mode_shapes
    from linmstmm.solve import UNRECORDED_ENGINE, FrequencyResult

    model = load_model("models/cantilever_tip_mass.toml")
    frequencies = natural_frequencies(model, 2).to_dict()
    modes = mode_shapes(model, 2).to_record()
    del frequencies["engine"], modes["engine"]
    assert FrequencyResult.from_dict(frequencies).engine == UNRECORDED_ENGINE
    assert ModalResult.from_dict(modes).engine == UNRECORDED_ENGINE
