"""The ``linmstmm`` command line against its contract (docs/cli.md)."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def run(*args):
    return subprocess.run([sys.executable, "-m", "linmstmm", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=120)


def test_freqs_json_follows_the_contract():
    result = run("freqs", "models/spring_mass_chain.toml", "--json", "--count", "4")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["model"] == "spring-mass chain"
    assert data["rigid_body_modes"] == 0 and data["ubar_order"] == 12
    assert isinstance(data["seconds"], float) and data["seconds"] > 0
    omega2 = np.array([(4 - np.sqrt(7)) / 3, (4 + np.sqrt(7)) / 3]) * 1000.0 / 2.0
    expected = np.repeat(np.sqrt(omega2) / (2 * np.pi), 3)[:4]
    np.testing.assert_allclose(data["frequencies_hz"], expected, rtol=1e-12)


@pytest.mark.parametrize("command", ["freqs", "modes", "fe"])
def test_fewer_modes_than_asked_for_are_noted(command):
    """6 degrees of freedom, 10 asked: the table and the JSON both carry the note."""
    table = run(command, "models/spring_mass_chain.toml", "--count", "10")
    assert table.returncode == 0, table.stderr
    assert "note: only 6 elastic natural frequencies exist" in table.stdout
    data = json.loads(run(command, "models/spring_mass_chain.toml", "--count", "10", "--json").stdout)
    assert len(data["frequencies_hz"]) == 6 and data["note"].startswith("only 6 elastic")


def test_freqs_fmax_and_count_stop_at_whichever_comes_first():
    by_fmax = json.loads(run("freqs", "models/cantilever_tip_mass.toml", "--json", "--fmax", "100").stdout)
    assert by_fmax["frequencies_hz"] == sorted(by_fmax["frequencies_hz"])
    assert len(by_fmax["frequencies_hz"]) == 4 and max(by_fmax["frequencies_hz"]) <= 100
    both = json.loads(run("freqs", "models/cantilever_tip_mass.toml", "--json", "--fmax", "100",
                          "--count", "3").stdout)
    # the same roots, reached from different search segments: equal to rounding
    np.testing.assert_allclose(both["frequencies_hz"], by_fmax["frequencies_hz"][:3], rtol=1e-13)


def test_freqs_table_is_readable():
    result = run("freqs", "models/cantilever_tip_mass.toml", "--count", "2")
    assert result.returncode == 0
    assert "cantilever with tip mass" in result.stdout and "6.7535" in result.stdout


def test_freqs_table_shows_the_digits_asked_for():
    """--digits 25, count cut inside a double root: the table prints what the JSON carries
    (f and ω at 25 digits), and the cut root is refined as the double root it is."""
    table = run("freqs", "models/cantilever_tip_mass.toml", "--count", "3", "--digits", "25")
    data = json.loads(run("freqs", "models/cantilever_tip_mass.toml", "--count", "3", "--digits", "25",
                          "--json").stdout)
    assert table.returncode == 0, table.stderr
    assert data["precision"] == "mpmath:25" and "precision: mpmath:25" in table.stdout
    for f, omega in zip(data["frequencies_hz_text"], data["omega_rad_s_text"]):
        assert len(f.replace(".", "")) == 25 and f"{f}  {omega}" in table.stdout


@pytest.mark.parametrize("args", [("freqs", "models/cantilever_tip_mass.toml", "--count", "0"),
                                  ("freqs", "models/cantilever_tip_mass.toml", "--fmax", "-3"),
                                  ("freqs", "models/cantilever_tip_mass.toml", "--bogus"),
                                  ("freqs", "models/cantilever_tip_mass.toml", "--root", "nowhere")])
def test_bad_options_exit_2_with_one_line(args):
    result = run(*args)
    assert result.returncode == 2
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr


@pytest.mark.parametrize("args, says", [
    (("freqs", "--fmax", "inf"), "--fmax: must be a positive finite number, got inf"),
    (("freqs", "--fmax", "nan"), "--fmax: must be a positive finite number, got nan"),
    (("freqs", "--count", "1e3"), "--count: must be a positive integer, got 1e3"),
    # a beam has infinitely many: these searched without end
    (("freqs", "--fmax", "1e30"), "fmax = 1e+30 Hz: at least"),
    (("modes", "--fmax", "1e7"), "fmax = 1e+07 Hz: at least 21363 natural frequencies lie below 1e+07 Hz"),
    (("fe", "--fmax", "1e7"), "fmax = 1e+07 Hz: at least 21363 natural frequencies lie below 1e+07 Hz"),
    (("scan", "--fmax", "1e7", "--plot", "never-written.png"), "fmax = 1e+07 Hz: at least 21363"),
    (("frf", "--point", "tip", "--direction", "y", "--fmax", "1e7", "--plot", "never-written.png"),
     "fmax = 1e+07 Hz (the modal sum takes every mode up to 2 x fmax): at least 42037 natural frequencies "
     "lie below 2e+07 Hz"),
])
def test_requests_without_end_exit_2_naming_the_option(args, says):
    command, *options = args
    result = run(command, "models/cantilever_tip_mass.toml", *options)
    assert result.returncode == 2 and result.stdout == ""
    assert result.stderr.count("\n") == 1 and says in result.stderr


#: A free 3.5 kg body and a spring whose far end carries no mass: six rigid-body
#: modes and no elastic one.
BODY_WITH_A_DANGLING_SPRING = """
name = "body with a dangling spring"
[points]
port = [0.2, 0.1, 0.0]
loose = [0.2, 0.1, 0.0]
[[rigid]]
name = "body"
ports = ["port"]
mass = 3.5
com = [0.0, 0.0, 0.0]
inertia = [0.1, 0.2, 0.3]
[[spring]]
name = "dangling"
ends = ["port", "loose"]
k = [1000.0, 2000.0, 3000.0, 10.0, 20.0, 30.0]
"""


def test_fe_finds_no_elastic_mode_where_none_exists(tmp_path):
    """``fe`` JSON and table agree with ``freqs``: exit 0, six rigid-body modes, no
    frequency (no mode row in the table), and a note that none exists."""
    path = tmp_path / "dangling.toml"
    path.write_text(BODY_WITH_A_DANGLING_SPRING)
    fe = run("fe", str(path), "--json")
    mstmm = run("freqs", str(path), "--json")
    assert fe.returncode == 0 == mstmm.returncode, fe.stderr + mstmm.stderr
    data, reference = json.loads(fe.stdout), json.loads(mstmm.stdout)
    assert data["frequencies_hz"] == reference["frequencies_hz"] == [] and data["error_estimate"] == []
    assert data["rigid_body_modes"] == reference["rigid_body_modes"] == 6
    assert data["note"].startswith("only 0 elastic natural frequencies exist")
    table = run("fe", str(path))
    assert table.returncode == 0, table.stderr
    lines = table.stdout.splitlines()
    assert "  rigid-body modes: 6" in lines and table.stdout.count("note: only 0 elastic") == 1
    header = next(i for i, line in enumerate(lines) if line.split()[:2] == ["mode", "f"])
    assert lines[header + 1].lstrip().startswith("solve time")


def test_version_is_the_package_version():
    import tomllib

    import linmstmm

    result = run("--version")
    assert result.returncode == 0, result.stderr
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert result.stdout.strip() == f"linmstmm {linmstmm.__version__}" == f"linmstmm {declared}"


def _commands():
    """The names of the registered subcommands."""
    from linmstmm.cli import build_parser

    parser = build_parser()
    (sub,) = [action for action in parser._actions if action.dest == "command"]
    return list(sub.choices)


@pytest.mark.parametrize("args", [(), ("-h",), ("--help",)])
def test_bare_and_help_list_every_command_with_an_example(args):
    from linmstmm.cli import COMMAND_EXAMPLES

    result = run(*args)
    assert result.returncode == 0, result.stderr
    assert sorted(COMMAND_EXAMPLES) == sorted(_commands())
    for name, example in COMMAND_EXAMPLES.items():
        assert f"  {name} " in result.stdout and example in result.stdout, name


def test_help_examples_are_valid_invocations():
    """Each example parses (its command, options and bundled files exist)."""
    from linmstmm.cli import COMMAND_EXAMPLES, build_parser

    for name, example in COMMAND_EXAMPLES.items():
        words = example.split()
        assert words[:2] == ["linmstmm", name]
        args = build_parser().parse_args(words[1:])
        assert args.command == name
        for value in vars(args).values():
            if isinstance(value, str) and value.startswith("models/"):
                assert (ROOT / value).is_file(), value
