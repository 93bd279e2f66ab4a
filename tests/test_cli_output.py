"""What the commands deliver: one name per quantity, one solve, CSV and JSON files, progress.

* ``freqs``, ``modes``, ``frf`` and ``response`` on one model: the keys they
  share (``model``, ``frequencies_hz``, ``rigid_body_modes``) carry the same
  values, and no other name for a natural frequency is left (``freqs
  --damped`` included);
* ``modes`` and ``freqs`` give identical frequencies on every bundled model,
  ``modes`` from one solve (one deduction and root finder);
* ``--csv`` files hold what the JSON holds, with the units in the headers;
  ``--output`` writes the JSON that ``--json`` prints;
* progress bars go to stderr only, and only to a terminal without ``--quiet``.
"""
from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest

import linmstmm.solve
from linmstmm import cli, mode_shapes, natural_frequencies
from linmstmm.model import load_model
from linmstmm.stages import listening
from builders import BUNDLED_MODELS

ROOT = Path(__file__).resolve().parents[1]
CANTILEVER = ROOT / "models" / "cantilever_tip_mass.toml"
CHAIN = ROOT / "models" / "spring_mass_chain.toml"
STEP = ROOT / "models" / "loads" / "cantilever_step.toml"  # [output] modes = 10


MODELS = BUNDLED_MODELS


@pytest.fixture
def run(capsys):
    """cli.main in this process: (status, stdout, stderr)."""
    def invoke(*argv):
        status = cli.main([str(a) for a in argv])
        out, err = capsys.readouterr()
        return status, out, err
    return invoke


def json_of(run, *argv) -> dict:
    status, out, err = run(*argv, "--json")
    assert status == 0, err
    return json.loads(out)


def test_shared_keys_have_one_name_and_one_value(run):
    """Ten elastic modes of the cantilever asked of each command: the same frequencies, to the bit."""
    results = {
        "freqs": json_of(run, "freqs", CANTILEVER, "--count", "10"),
        "modes": json_of(run, "modes", CANTILEVER, "--count", "10"),
        "frf": json_of(run, "frf", CANTILEVER, "--point", "tip", "--direction", "z", "--fmax", "50",
                       "--modes", "10", "--frequencies", "5"),
        "response": json_of(run, "response", CANTILEVER, STEP),
    }
    reference = results["freqs"]
    assert len(reference["frequencies_hz"]) == 10 and reference["rigid_body_modes"] == 0
    for command, data in results.items():
        for key in ("model", "frequencies_hz", "rigid_body_modes"):
            assert data[key] == reference[key], (command, key)
        assert not [key for key in data if "natural_freq" in key], command
    assert results["frf"]["excitation_hz"] == [10.0, 20.0, 30.0, 40.0, 50.0]


def test_freqs_damped_follows_the_naming_scheme(run):
    """Without damping the damped roots are the undamped ones: ``frequencies_hz`` (|s| / 2π) and
    ``damped_frequencies_hz`` are then the frequencies ``freqs`` gives; no other name is used."""
    undamped = json_of(run, "freqs", CANTILEVER, "--count", "4")
    damped = json_of(run, "freqs", CANTILEVER, "--count", "4", "--damped")
    for key in ("model", "rigid_body_modes"):
        assert damped[key] == undamped[key], key
    assert not [key for key in damped if "natural_freq" in key or key.endswith("_freq_hz")]
    for key in ("frequencies_hz", "damped_frequencies_hz", "undamped_frequencies_hz"):
        np.testing.assert_allclose(damped[key], undamped["frequencies_hz"], rtol=1e-10, err_msg=key)
    assert np.abs(damped["damping_ratio"]).max() < 1e-10


@pytest.mark.parametrize("path", MODELS, ids=[str(p.relative_to(ROOT / "models")) for p in MODELS])
def test_modes_and_freqs_agree_to_the_last_digit_from_one_solve(path, run, monkeypatch):
    solves = []
    finder = linmstmm.solve.frequency_finder

    def counted(*args, **options):
        solves.append(args)
        return finder(*args, **options)

    frequencies = json_of(run, "freqs", path)
    monkeypatch.setattr(linmstmm.solve, "frequency_finder", counted)
    modes = json_of(run, "modes", path)
    assert len(solves) == 1
    rigid = modes["rigid_body_modes"]
    assert rigid == frequencies["rigid_body_modes"]
    assert modes["frequencies_hz"][:rigid] == [0.0] * rigid
    elastic = modes["frequencies_hz"][rigid:]
    assert elastic[:len(frequencies["frequencies_hz"])] == frequencies["frequencies_hz"]
    # a repeated frequency comes whole: anything beyond the count repeats the last one
    assert set(elastic[len(frequencies["frequencies_hz"]):]) <= {frequencies["frequencies_hz"][-1]}


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path, newline="") as file:
        header, *rows = list(csv.reader(file))
    return header, np.array(rows, dtype=float)


def test_freqs_csv_and_output_hold_the_json(run, tmp_path):
    status, table, _ = run("freqs", CANTILEVER, "--count", "4", "--csv", tmp_path / "f.csv",
                           "--output", tmp_path / "f.json")
    assert status == 0 and "wrote" in table and "mode" in table
    data = json_of(run, "freqs", CANTILEVER, "--count", "4")
    saved = json.loads((tmp_path / "f.json").read_text())
    assert {k: v for k, v in saved.items() if k != "seconds"} == {k: v for k, v in data.items() if k != "seconds"}
    header, rows = read_csv(tmp_path / "f.csv")
    assert header == ["mode", "frequency [Hz]", "omega [rad/s]"]
    assert rows[:, 0].tolist() == [1, 2, 3, 4] and rows[:, 1].tolist() == data["frequencies_hz"]
    np.testing.assert_allclose(rows[:, 2], 2 * np.pi * rows[:, 1], rtol=1e-15)


def test_freqs_csv_carries_the_mpmath_digits(run, tmp_path):
    status, _, err = run("freqs", CANTILEVER, "--count", "1", "--digits", "25", "--csv", tmp_path / "f.csv")
    assert status == 0, err
    data = json_of(run, "freqs", CANTILEVER, "--count", "1", "--digits", "25")
    row = (tmp_path / "f.csv").read_text().splitlines()[1].split(",")
    assert row[1:] == [data["frequencies_hz_text"][0], data["omega_rad_s_text"][0]]


@pytest.mark.parametrize("normalization, units", [("mass", ("m/sqrt(kg)", "rad/sqrt(kg)")), ("max", ("m", "rad"))])
def test_modes_csv_rows_are_modes_with_shapes_at_points(run, tmp_path, normalization, units):
    options = ("--count", "2", "--normalization", normalization)
    assert run("modes", CHAIN, *options, "--csv", tmp_path / "m.csv")[0] == 0
    data = json_of(run, "modes", CHAIN, *options)
    header, rows = read_csv(tmp_path / "m.csv")
    assert header[:3] == ["mode", "frequency [Hz]", "modal mass [kg]"]
    assert header[3:9] == [f"g0.{c} [{units[0]}]" for c in "xyz"] + [f"g0.r{c} [{units[1]}]" for c in "xyz"]
    assert len(header) == 3 + 6 * len(data["points"]) and len(rows) == len(data["frequencies_hz"]) == 3
    assert rows[:, 1].tolist() == data["frequencies_hz"] and rows[:, 2].tolist() == data["modal_mass"]
    b2 = header.index(f"b2.x [{units[0]}]")
    assert rows[:, b2:b2 + 6].tolist() == data["point_displacements"]["b2"]


def test_frf_csv_holds_the_receptance(run, tmp_path):
    options = ("--point", "b2", "--direction", "x", "--fmax", "10", "--frequencies", "5", "--zeta", "0.05",
               "--response-points", "b2", "a1")
    assert run("frf", CHAIN, *options, "--csv", tmp_path / "h.csv")[0] == 0
    data = json_of(run, "frf", CHAIN, *options)
    header, rows = read_csv(tmp_path / "h.csv")
    assert header[0] == "excitation frequency [Hz]" and rows[:, 0].tolist() == data["excitation_hz"]
    assert header[1:3] == ["b2.x.real [m/N]", "b2.x.imag [m/N]"] and header[-1] == "a1.rz.imag [rad/N]"
    for point in ("b2", "a1"):
        for c, name in enumerate(("x", "y", "z", "rx", "ry", "rz")):
            unit = data["receptance_units"][c]
            real = header.index(f"{point}.{name}.real [{unit}]")
            assert rows[:, real].tolist() == [row[c] for row in data["receptance"][point]["real"]]
            assert rows[:, real + 1].tolist() == [row[c] for row in data["receptance"][point]["imag"]]


def test_response_csv_holds_the_histories(run, tmp_path):
    assert run("response", CANTILEVER, STEP, "--csv", tmp_path / "r.csv", "--quiet")[0] == 0
    data = json_of(run, "response", CANTILEVER, STEP)
    header, rows = read_csv(tmp_path / "r.csv")
    assert header[0] == "time [s]" and rows[:, 0].tolist() == data["times"]
    assert len(header) == 1 + 18 * len(data["points"])
    for quantity in ("displacement", "velocity", "acceleration"):
        for c, name in enumerate(("x", "y", "z", "rx", "ry", "rz")):
            column = header.index(f"tip.{quantity}.{name} [{data['units'][quantity][c]}]")
            assert rows[:, column].tolist() == [row[c] for row in data[quantity]["tip"]]


def test_an_output_file_that_cannot_be_written_names_the_option(run, tmp_path):
    status, out, err = run("freqs", CHAIN, "--csv", tmp_path / "missing" / "f.csv")
    assert status == 2 and out == "" and "key '--csv'" in err and err.count("\n") == 1
    status, _, err = run("freqs", CHAIN, "--output", tmp_path / "missing" / "f.json")
    assert status == 2 and "key '--output'" in err


class Terminal(io.StringIO):
    """A stderr that says it is a terminal."""

    def isatty(self):
        return True


@pytest.mark.parametrize("quiet", [False, True])
def test_progress_goes_to_a_terminal_only_and_never_to_stdout(tmp_path, monkeypatch, capsys, quiet):
    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    argv = ["modes", str(CANTILEVER), "--count", "2", "--plot", str(tmp_path), "--json"]
    assert cli.main(argv + (["--quiet"] if quiet else [])) == 0
    data = json.loads(capsys.readouterr().out)  # stdout is the JSON alone
    assert len(data["files"]) == 2
    assert ("mode figures" in terminal.getvalue()) is not quiet


@pytest.mark.parametrize("quiet", [False, True])
def test_a_long_solve_shows_its_stages_on_a_terminal(monkeypatch, capsys, quiet):
    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    argv = ["freqs", str(CANTILEVER), "--count", "2", "--digits", "20", "--json"]
    assert cli.main(argv + (["--quiet"] if quiet else [])) == 0
    assert json.loads(capsys.readouterr().out)["precision"] == "mpmath:20"
    shown = terminal.getvalue()
    for stage in ("deducing Ubar_all", "finding roots", "refining in mpmath to 20 digits"):
        assert (stage in shown) is not quiet, stage


def test_the_solvers_report_their_stages_in_order():
    model = load_model(CANTILEVER)
    heard = []
    with listening(heard.append):
        natural_frequencies(model, count=2)
        mode_shapes(model, 2)
    assert heard == ["deducing Ubar_all", "finding roots"] * 2 + ["mode shapes"]
    natural_frequencies(model, count=1)  # nobody listening: nothing heard
    assert len(heard) == 5


def test_the_mpmath_refinement_reports_each_root():
    """--digits refines root after root, a double root once: each is a stage of its own."""
    heard = []
    with listening(heard.append):
        natural_frequencies(load_model(CANTILEVER), count=3, digits=20)
    assert heard[3:] == ["mpmath: roots 1-2 of 3 (6.75357 Hz)", "mpmath: root 3 of 3 (50.8992 Hz)"]


def test_no_progress_off_a_terminal(run, tmp_path):
    status, _, err = run("modes", CANTILEVER, "--count", "2", "--plot", tmp_path)
    assert status == 0 and "mode figures" not in err
