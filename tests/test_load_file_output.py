"""The [output] times of a load file: a step that fits in the duration, and a
response no larger than MAX_RESPONSE_VALUES values; anything else is refused
with one line naming the file, ``[output]`` and ``step``."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from builders import spring_mass_chain

from linmstmm.loads import MAX_RESPONSE_VALUES, load_loads
from linmstmm.model import ModelError

ROOT = Path(__file__).resolve().parents[1]
LOAD = '[[load]]\npoint = "b1"\nforce = [0.0, 10.0, 0.0]\ntime = { kind = "step" }\n\n[output]\n'


def load_file(tmp_path, output: str) -> Path:
    path = tmp_path / "loads.toml"
    path.write_text(LOAD + output)
    return path


@pytest.mark.parametrize("output, times", [
    ("duration = 1.0\nstep = 1.0\n", [0.0, 1.0]),
    ("duration = 1.0\nstep = 0.25\n", [0.0, 0.25, 0.5, 0.75, 1.0]),
    ("duration = 1.0\nstep = 0.3\n", [0.0, 0.3, 0.6, 0.9]),
])
def test_output_times_run_from_zero_in_steps_up_to_the_duration(tmp_path, output, times):
    case = load_loads(load_file(tmp_path, output), spring_mass_chain())
    np.testing.assert_allclose(case.times, times, rtol=1e-15)


def test_a_step_longer_than_the_duration_is_refused(tmp_path):
    path = load_file(tmp_path, "duration = 1.0\nstep = 5.0\n")
    with pytest.raises(ModelError) as error:
        load_loads(path, spring_mass_chain())
    assert error.value.key == "step" and error.value.element == "[output]"
    assert str(path) in str(error.value) and "longer than the duration" in error.value.message


def test_a_response_too_large_to_hold_is_refused_before_it_is_built(tmp_path):
    """One point and one mode: 21 values per output time; the limit is on the
    response's size, whatever the units of time."""
    model = spring_mass_chain()
    per_time = 18 * 1 + 3 * 1
    largest = MAX_RESPONSE_VALUES // per_time  # output times
    for scale in (1.0, 1e-6, 1e6):  # the same request in other units of time
        fits = f'points = ["b1"]\nmodes = 1\nduration = {(largest - 1) * scale!r}\nstep = {scale!r}\n'
        assert load_loads(load_file(tmp_path, fits), model).times.size == largest
        over = f'points = ["b1"]\nmodes = 1\nduration = {largest * scale!r}\nstep = {scale!r}\n'
        with pytest.raises(ModelError) as error:
            load_loads(load_file(tmp_path, over), model)
        assert error.value.key == "step" and "may hold" in error.value.message
    huge = load_file(tmp_path, "duration = 1000.0\nstep = 1e-300\n")
    with pytest.raises(ModelError, match="may hold"):
        load_loads(huge, model)


def test_the_command_refuses_with_exit_status_2_and_one_line(tmp_path):
    model = tmp_path / "chain.toml"
    model.write_text((ROOT / "models" / "spring_mass_chain.toml").read_text())
    loads = load_file(tmp_path, "duration = 1000.0\nstep = 1e-6\n")
    run = subprocess.run([sys.executable, "-m", "linmstmm", "response", str(model), str(loads)],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 2 and run.stdout == ""
    assert run.stderr.count("\n") == 1 and "key 'step'" in run.stderr and str(loads) in run.stderr
