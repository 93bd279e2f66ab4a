"""Model updating (``linmstmm fit``, :mod:`linmstmm.fit`).

The measured data are made by the program's own solvers on an independently
edited model file (the TOML document changed and written back without
linmstmm): two values of the spring-mass chain perturbed, its frequencies from
``linmstmm freqs`` (and shapes from ``mode_shapes`` on that file); the fit
starts from the unperturbed file and must recover the perturbed values.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from test_sweep import CHAIN, edited_file, run_cli

from linmstmm.model import load_model
from linmstmm.modes import mode_shapes
from linmstmm.uff import write_uff

MODELS = Path(__file__).resolve().parents[1] / "models"

PERTURBED = {"rigid.m2.mass": 2.3, "spring.k2.k[0]": 1300.0}  # from 2 kg and 1000 N/m


@pytest.fixture(scope="module")
def perturbed(tmp_path_factory):
    """The chain file with PERTURBED written into it."""
    return edited_file(CHAIN, PERTURBED, tmp_path_factory.mktemp("perturbed"))


def write_csv(path: Path, header, rows) -> Path:
    path.write_text("\n".join(",".join(map(str, row)) for row in [header, *rows]) + "\n")
    return path


def own_frequencies(model_file, folder: Path) -> tuple[list, Path]:
    """(the lowest 6 frequencies ``linmstmm freqs`` gives for ``model_file``, Hz; a
    measured-frequency CSV of them in ``folder``)."""
    status, out, err = run_cli("freqs", model_file, "--count", 6, "--json")
    assert status == 0, err
    measured = json.loads(out)["frequencies_hz"]
    return measured, write_csv(folder / "measured.csv", ["frequency [Hz]"], [[repr(float(f))] for f in measured])


def test_two_values_are_recovered_from_the_frequencies_freqs_gives(perturbed, tmp_path):
    measured, csv_file = own_frequencies(perturbed, tmp_path)
    status, out, err = run_cli("fit", CHAIN, csv_file, "--vary", "rigid.m2.mass=1:4",
                               "--vary", "spring.k2.k[0]=200:5000", "--json")
    assert status == 0, err
    data = json.loads(out)
    fitted = {p["key"]: p["fitted"] for p in data["parameters"]}
    assert [p["initial"] for p in data["parameters"]] == [2.0, 1000.0]
    for key, value in PERTURBED.items():
        assert fitted[key] == pytest.approx(value, rel=1e-6)
    assert data["converged"] and data["ranks"] == list(range(6)) and data["mac"] is None
    np.testing.assert_allclose(data["fitted_hz"], measured, rtol=1e-9)
    # exact data: the intervals shrink to the rounding of the frequencies
    assert all(p["sigma"] < 1e-6 * p["fitted"] for p in data["parameters"])


def test_measured_shapes_pair_the_modes_by_mac(tmp_path):
    """Only the two x modes measured (x at both masses' ports): MAC pairing finds them
    among the model's modes, whatever their ranks, and both values are recovered from
    them. The middle spring's y and z stiffnesses are set apart (700 and 500 N/m) in
    both files, so that no frequency of the start is repeated (the sensitivities within
    a repeated frequency are those of its ascending branches, not of a measured shape)."""
    apart = {"spring.k2.k[1]": 700.0, "spring.k2.k[2]": 500.0}
    start = edited_file(CHAIN, apart, tmp_path)
    modes = mode_shapes(load_model(edited_file(CHAIN, {**apart, **PERTURBED}, tmp_path)), count=6, rigid_body=False)
    x = [k for k in range(6) if np.abs(modes.point_displacements["a1"][k, 0]) > 1e-6]
    assert len(x) == 2 and x != [0, 1]  # the x modes are not the two lowest
    rows = [[repr(float(modes.frequencies_hz[k])), repr(float(modes.point_displacements["a1"][k, 0])),
             repr(float(modes.point_displacements["a2"][k, 0]))] for k in x]
    csv_file = write_csv(tmp_path / "shapes.csv", ["frequency [Hz]", "a1.x", "a2.x"], rows)
    status, out, err = run_cli("fit", start, csv_file, "--vary", "rigid.m2.mass=1:4",
                               "--vary", "spring.k2.k[0]=200:5000", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert data["ranks"] == x and min(data["mac"]) > 0.999
    fitted = {p["key"]: p["fitted"] for p in data["parameters"]}
    for key, value in PERTURBED.items():
        assert fitted[key] == pytest.approx(value, rel=1e-6)


def test_modes_from_a_universal_file(tmp_path):
    """The perturbed chain's six modes written as a universal file (datasets 15 and 55, as
    ``modes --uff`` writes them): MAC pairs them and both values are recovered. E13.5 keeps
    six significant digits of each frequency (rounding up to 5e-6), so the values come back
    to that order, not to the 1e-6 of the CSV tests."""
    apart = {"spring.k2.k[1]": 700.0, "spring.k2.k[2]": 500.0}
    start = edited_file(CHAIN, apart, tmp_path)
    truth = load_model(edited_file(CHAIN, {**apart, **PERTURBED}, tmp_path))
    uff_file = tmp_path / "measured.uff"
    write_uff(mode_shapes(truth, count=6, rigid_body=False), truth, uff_file)
    status, out, err = run_cli("fit", start, uff_file, "--vary", "rigid.m2.mass=1:4",
                               "--vary", "spring.k2.k[0]=200:5000", "--json")
    assert status == 0, err
    data = json.loads(out)
    assert sorted(data["ranks"]) == list(range(6)) and min(data["mac"]) > 0.999
    fitted = {p["key"]: p["fitted"] for p in data["parameters"]}
    for key, value in PERTURBED.items():
        assert fitted[key] == pytest.approx(value, rel=1e-5)


def test_a_universal_file_of_another_model_is_refused(tmp_path):
    """Its nodes are not at the chain's points: exit status 2, one line naming the node."""
    other = load_model(MODELS / "cantilever_tip_mass.toml")
    uff_file = tmp_path / "other.uff"
    write_uff(mode_shapes(other, count=2), other, uff_file)
    status, out, err = run_cli("fit", CHAIN, uff_file, "--vary", "rigid.m2.mass=1:4")
    assert status == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "node" in err and "another model" in err


def test_intervals_are_those_of_the_linearised_problem(perturbed, tmp_path):
    """Measured frequencies off by ±1 %: the fit no longer matches them, and its
    1-sigma intervals are √diag(s² (JᵀJ)⁻¹) with J from central differences of the
    frequencies freqs gives (relative residuals, s² = Σr² / (m − n))."""
    from linmstmm.parameters import parse_key, with_values
    from linmstmm.solve import natural_frequencies

    status, out, _ = run_cli("freqs", perturbed, "--count", 6, "--json")
    measured = np.array(json.loads(out)["frequencies_hz"]) * (1 + 0.01 * np.array([1, -1, 1, 1, -1, 1]))
    csv_file = write_csv(tmp_path / "noisy.csv", ["frequency [Hz]"], [[repr(float(f))] for f in measured])
    status, out, err = run_cli("fit", CHAIN, csv_file, "--vary", "rigid.m2.mass=1:4",
                               "--vary", "spring.k2.k[0]=200:5000", "--json")
    assert status == 0, err
    data = json.loads(out)
    model = load_model(CHAIN)
    keys = [parse_key(model, p["key"]) for p in data["parameters"]]
    values = np.array([p["fitted"] for p in data["parameters"]])

    def relative(v):
        edited = with_values(model, dict(zip(keys, v)))
        return natural_frequencies(edited, count=6, engine="numpy").frequencies_hz / measured - 1

    jacobian = np.column_stack([(relative(values + h) - relative(values - h)) / (2 * h[j])
                                for j, h in enumerate(np.diag(values * 1e-5))])
    r = relative(values)
    sigma = np.sqrt(np.diag(np.linalg.inv(jacobian.T @ jacobian) * (r @ r) / (6 - 2)))
    np.testing.assert_allclose([p["sigma"] for p in data["parameters"]], sigma, rtol=1e-4)


@pytest.mark.parametrize("argv, csv_text, message", [
    (["--vary", "rigid.m2.mass=4:1"], "frequency [Hz]\n3.0\n", "START < STOP"),
    (["--vary", "rigid.m2.mass=3:4"], "frequency [Hz]\n3.0\n", "key 'rigid.m2.mass': the model's value 2 is not inside"),
    (["--vary", "rigid.m2.mas=1:4"], "frequency [Hz]\n3.0\n", "did you mean 'rigid.m2.mass'"),
    (["--vary", "rigid.m2.mass=1:4"], "f\n3.0\n", "needs a column 'frequency [Hz]'"),
    (["--vary", "rigid.m2.mass=1:4"], "frequency [Hz],tip.x\n3.0,1\n", "key 'tip.x': a shape column is POINT.DIR"),
    (["--vary", "rigid.m2.mass=1:4"], "frequency [Hz]\nthree\n", "key 'frequency [Hz]': 'three' is not a number"),
    (["--vary", "rigid.m2.mass=1:4"], None, "cannot read the measured file: No such file or directory"),
])
def test_bad_requests_exit_2_with_one_line(argv, csv_text, message, tmp_path):
    csv_file = tmp_path / "measured.csv"
    if csv_text is not None:
        csv_file.write_text(csv_text)
    status, out, err = run_cli("fit", CHAIN, csv_file, *argv)
    assert status == 2 and out == ""
    assert err.count("\n") == 1 and message in err and "Traceback" not in err, err


def test_values_the_frequencies_do_not_separate_have_no_interval(tmp_path):
    """A bare cantilever's frequencies depend on E and ρ only through E/ρ: fitted
    together from its own frequencies, neither is determined, and both 1-sigma are
    null (the inverse of the singular JᵀJ gave a finite 1.5e5 Pa)."""
    text = (MODELS / "cantilever_tip_mass.toml").read_text()
    bare = tmp_path / "bare.toml"
    bare.write_text(text[:text.index("[[rigid]]")] + text[text.index("[boundary]"):])
    _, csv_file = own_frequencies(bare, tmp_path)
    status, out, err = run_cli("fit", bare, csv_file, "--vary", "beam.arm.E=1e11:3e11",
                               "--vary", "beam.arm.rho=5000:9000", "--json")
    assert status == 0, err
    assert [p["sigma"] for p in json.loads(out)["parameters"]] == [None, None]
