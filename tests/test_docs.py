"""The guides in docs/ and the README do what they say.

* every ```python block of docs/*.md and README.md runs, from the repository
  root, in a fresh namespace (the blocks assert their own results against
  closed forms or the finite-element route where they state one);
* every ``linmstmm ...`` line of a ```sh block in docs/cli.md runs through the
  command line's entry point with exit status 0, unless it is marked
  ``# slow``; the top-level keys of each ``--json`` output are documented there;
* every ```toml block of docs/model-format.md is valid TOML, and each complete
  model (one with ``name`` and ``[points]``) loads; each complete model with a
  joint (``release``) gives the FE route's frequencies and zero-frequency
  count; the load-file example of docs/cli.md loads for the model it was
  written for;
* relative links between the guides lead to existing files and headings, and
  no tracked text points at a folder outside the repository.
"""
from __future__ import annotations

import contextlib
import io
import json
import re
import shlex
import subprocess
import tomllib
from pathlib import Path

import numpy as np
import pytest

from linmstmm.cli import main
from linmstmm.fe import fe_frequencies
from linmstmm.model import ModelError, load_model
from linmstmm.response import load_loads
from linmstmm.solve import natural_frequencies

REPO = Path(__file__).resolve().parents[1]
GUIDES = sorted((REPO / "docs").glob("*.md"))
SLOW = "# slow"


def blocks(path: Path, language: str) -> list[str]:
    """The fenced code blocks of ``language`` in the Markdown file ``path``, in order."""
    return re.findall(rf"^```{language}\n(.*?)^```", path.read_text(), re.S | re.M)


def cases(paths, language):
    """pytest parameters (path, index, block), named file#index."""
    return [pytest.param(path, index, block, id=f"{path.name}#{index}")
            for path in paths for index, block in enumerate(blocks(path, language))]


def cli_lines():
    """The ``linmstmm ...`` command lines of docs/cli.md's sh blocks, slow ones apart."""
    lines = [line.strip() for block in blocks(REPO / "docs" / "cli.md", "sh")
             for line in block.splitlines() if line.strip().startswith("linmstmm")]
    return [pytest.param(line, id=line, marks=[pytest.mark.skip("marked slow")] if SLOW in line else [])
            for line in lines]


def test_the_guides_exist():
    assert {p.name for p in GUIDES} >= {"model-format.md", "cli.md", "api.md", "method.md"}
    assert blocks(REPO / "docs" / "api.md", "python") and cli_lines()


@pytest.mark.parametrize("path, index, code", cases([*GUIDES, REPO / "README.md"], "python"))
def test_python_example_runs(path, index, code, monkeypatch, capsys):
    monkeypatch.chdir(REPO)
    exec(compile(code, f"{path.name} python block {index}", "exec"), {"__name__": "__docs__"})


@pytest.mark.parametrize("line", cli_lines())
def test_cli_example_runs(line, tmp_path, monkeypatch):
    """Run in a scratch folder (figures land there) that sees the bundled models."""
    (tmp_path / "models").symlink_to(REPO / "models")
    monkeypatch.chdir(tmp_path)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(shlex.split(line, comments=True)[1:])
        except SystemExit as done:  # --version and -h end through argparse
            status = done.code
    assert status == 0, err.getvalue()
    if "--json" in line.split():
        documented = cli_section(line.split()[1]) + cli_section("freqs")  # fe and modes refer to freqs
        for key in json.loads(out.getvalue()):
            assert f"`{key}`" in documented, f"key {key!r} is not documented"


def cli_section(command: str) -> str:
    """The text of docs/cli.md under the heading of ``linmstmm COMMAND``, up to the next one."""
    text = (REPO / "docs" / "cli.md").read_text()
    return text.split(f"## `linmstmm {command}`\n", 1)[1].split("\n## ", 1)[0]


@pytest.mark.parametrize("path, index, text", cases([REPO / "docs" / "model-format.md"], "toml"))
def test_model_format_toml_examples_are_valid(path, index, text, tmp_path):
    data = tomllib.loads(text)
    if "name" in data and "points" in data:
        file = tmp_path / "example.toml"
        file.write_text(text)
        load_model(file)


def joint_examples():
    """The complete models of docs/model-format.md that have a joint, named by their ``name``."""
    models = [tomllib.loads(text) | {"text": text} for text in blocks(REPO / "docs" / "model-format.md", "toml")]
    return [pytest.param(model["text"], id=model["name"]) for model in models
            if "points" in model and any("release" in spring for spring in model.get("spring", []))]


def test_the_guide_shows_every_joint_kind():
    assert len(joint_examples()) == 4


@pytest.mark.parametrize("text", joint_examples())
def test_joint_examples_agree_with_the_fe_route(text, tmp_path):
    file = tmp_path / "joint.toml"
    file.write_text(text)
    model = load_model(file)
    result, check = natural_frequencies(model, count=3), fe_frequencies(model, count=3)
    assert result.rigid_body_modes == check.rigid_body_modes
    np.testing.assert_allclose(result.frequencies_hz, check.frequencies_hz, rtol=1e-8)


def test_model_format_example_is_the_test_data_file():
    """tests/data/good/cantilever.toml says it is the guide's example verbatim."""
    data_file = (REPO / "tests" / "data" / "good" / "cantilever.toml").read_text()
    body = data_file.split("\n", 1)[1]
    assert body in blocks(REPO / "docs" / "model-format.md", "toml")


def test_cli_load_file_example_loads(tmp_path):
    (example,) = blocks(REPO / "docs" / "cli.md", "toml")
    file = tmp_path / "loads.toml"
    file.write_text(example)
    case = load_loads(file, load_model(REPO / "models" / "cantilever_tip_mass.toml"))
    assert case.points == ("tip",) and case.modes == 10


def _anchor(heading: str) -> str:
    """The anchor a code host gives a Markdown heading."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


@pytest.mark.parametrize("path", [*GUIDES, REPO / "README.md"], ids=lambda p: p.name)
def test_relative_links_resolve(path):
    for target in re.findall(r"\]\(([^)\s]+)\)", path.read_text()):
        if re.match(r"[a-z]+://", target):
            continue
        file, _, anchor = target.partition("#")
        linked = (path.parent / file).resolve() if file else path
        assert linked.exists(), target
        if anchor:
            headings = re.findall(r"^#+ (.*)$", linked.read_text(), re.M)
            assert anchor in {_anchor(h) for h in headings}, target


def test_nothing_points_outside_the_repository():
    tracked = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True,
                             check=True).stdout.split()
    pattern = re.compile(r"(\.\.[/\\])+shared|shared[/\\](spec|seeds)")
    offenders = []
    for name in tracked:
        path = REPO / name
        if path.suffix in {".py", ".md", ".toml", ".txt", ".cfg"} and path.is_file():
            offenders += [f"{name}:{n}" for n, line in enumerate(path.read_text().splitlines(), 1)
                          if pattern.search(line)]
    assert offenders == []


#: (example model of docs/model-format.md, line after which a key is added, its section heading)
TABLES = [
    ('name = "cantilever', 'name = "cantilever with tip mass"', "## Top level"),
    ('name = "cantilever', "[[beam]]", "## Beams: `[[beam]]`"),
    ('name = "cantilever', "[[rigid]]", "## Rigid bodies: `[[rigid]]`"),
    ('name = "spring-mass chain', "[[spring]]", "## Springs: `[[spring]]`"),
    ('name = "portal frame', "[damping]", "## Damping: `[damping]`"),
]


@pytest.mark.parametrize("example, after, heading", TABLES, ids=[t[2] for t in TABLES])
def test_model_format_documents_every_key_the_loader_allows(example, after, heading, tmp_path):
    """The loader names its allowed keys when it meets an unknown one; each is in the guide."""
    guide = REPO / "docs" / "model-format.md"
    lines = next(b for b in blocks(guide, "toml") if b.startswith(example)).splitlines()
    at = lines.index(after) + 1
    file = tmp_path / "unknown_key.toml"
    file.write_text("\n".join(lines[:at] + ["bogus_key = 1"] + lines[at:]) + "\n")
    with pytest.raises(ModelError, match="allowed keys") as error:
        load_model(file)
    section = guide.read_text().split(heading + "\n", 1)[1].split("\n## ", 1)[0]
    for key in error.value.message.split("allowed keys: ")[1].split(", "):
        assert re.search(rf"`(\[\[?)?{key}(\]\]?)?`", section), f"{heading}: {key}"


def test_cli_guide_documents_every_option():
    """Each command's options, as the parser registers them, appear in its section of docs/cli.md."""
    from linmstmm.cli import build_parser

    (commands,) = [a for a in build_parser()._actions if a.dest == "command"]
    for name, parser in commands.choices.items():
        section = cli_section(name)
        for action in parser._actions:
            for option in action.option_strings:
                if option not in ("-h", "--help"):
                    assert option in section, f"linmstmm {name} {option}"
