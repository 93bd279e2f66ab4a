"""Every key of the model format acts or is refused.

For each key the loader accepts (top level, ``[points]``, ``[[rigid]]``,
``[[beam]]``, ``[[spring]]``, the forms of ``[boundary]``, ``[damping]``) one
case loads ``BASE``, changes that key's value, and checks that an output the
key should reach changes: the natural frequencies, the mode shapes, the
modal response (damping), or the ``linmstmm check`` report (names and the
description); or that the loader refuses the change with a one-line message
naming the key. The keys the loader accepts are read from its own
"allowed keys" messages, so a key added to the format without a case here
fails :func:`test_every_accepted_key_has_a_case`.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass

import numpy as np
import pytest

from linmstmm import cli
from linmstmm.model import ModelError, load_model
from linmstmm.modes import mode_shapes
from linmstmm.response import LoadCase, PointLoad, impulse, respond
from linmstmm.solve import natural_frequencies

#: A cantilever "arm" root -> tip; two springs in series, "mount" tip -> hinge and
#: "link" hinge -> cap (the three points coincide); a rigid body "payload" on cap,
#: its mass centre off every axis. Section, stiffnesses and inertia all differ by
#: direction, so every direction of every element shows in the lowest modes.
BASE = """\
name = "every key"

[points]
root = [0.0, 0.0, 0.0]
tip = [1.5, 0.0, 0.0]
hinge = [1.5, 0.0, 0.0]
cap = [1.5, 0.0, 0.0]

[[beam]]
name = "arm"
ends = ["root", "tip"]
E = 2.1e11
G = 8.1e10
rho = 7850.0
A = 1.0e-3
Iy = 2.0e-7
Iz = 3.0e-7
J = 4.0e-7

[[spring]]
name = "mount"
ends = ["tip", "hinge"]
k = [2e6, 3e6, 4e6, 5e4, 6e4, 7e4]

[[spring]]
name = "link"
ends = ["hinge", "cap"]
k = [3e6, 4e6, 5e6, 6e4, 7e4, 8e4]

[[rigid]]
name = "payload"
ports = ["cap"]
mass = 5.0
com = [1.6, 0.05, 0.1]
inertia = [0.1, 0.2, 0.25]

[boundary]
root = "fixed"
"""

#: An output differs when some entry moves by more than this fraction of the
#: largest entry of its kind (far above rounding, far below any change below).
CHANGED = 1e-6
#: Modes in the frequency and shape outputs (the first 8 reach 120 Hz in BASE).
MODES = 8


@dataclass(frozen=True)
class Case:
    """Change ``old`` to ``new`` in BASE (``old`` occurs once): ``key`` of
    ``section`` must change ``output``, or (output "refused") be refused."""

    section: str
    key: str
    old: str
    new: str
    output: str

    def __str__(self):
        return f"{self.section}.{self.key}"


def after(line, extra):
    """(old, new) of a case adding the line ``extra`` after ``line``."""
    return line, f"{line}\n{extra}"


BEAM = 'ends = ["root", "tip"]'
MOUNT = 'ends = ["tip", "hinge"]'
LINK = 'k = [3e6, 4e6, 5e6, 6e4, 7e4, 8e4]'
PAYLOAD = 'name = "payload"'

CASES = [
    Case("top", "name", 'name = "every key"', 'name = "any key"', "check"),
    Case("top", "description", *after('name = "every key"', 'description = "a cantilever"'), "check"),
    Case("points", "root", "root = [0.0, 0.0, 0.0]", "root = [-0.5, 0.0, 0.0]", "frequencies"),
    Case("points", "tip", "tip = [1.5, 0.0, 0.0]", "tip = [1.5, 0.0, 0.2]", "refused"),
    Case("rigid", "name", PAYLOAD, 'name = "load"', "shapes"),
    Case("rigid", "ports", 'ports = ["cap"]', 'ports = ["hinge"]', "frequencies"),
    Case("rigid", "mass", "mass = 5.0", "mass = 8.0", "frequencies"),
    Case("rigid", "com", "com = [1.6, 0.05, 0.1]", "com = [1.6, -0.05, 0.2]", "frequencies"),
    Case("rigid", "inertia", "inertia = [0.1, 0.2, 0.25]", "inertia = [0.3, 0.2, 0.25]", "frequencies"),
    Case("beam", "name", 'name = "arm"', 'name = "boom"', "shapes"),
    Case("beam", "ends", BEAM, 'ends = ["root", "hinge"]', "frequencies"),
    Case("beam", "E", "E = 2.1e11", "E = 1.0e11", "frequencies"),
    Case("beam", "G", "G = 8.1e10", "G = 4.0e10", "frequencies"),
    Case("beam", "rho", "rho = 7850.0", "rho = 2700.0", "frequencies"),
    Case("beam", "A", "A = 1.0e-3", "A = 2.0e-3", "frequencies"),
    Case("beam", "Iy", "Iy = 2.0e-7", "Iy = 1.0e-7", "frequencies"),
    Case("beam", "Iz", "Iz = 3.0e-7", "Iz = 1.5e-7", "frequencies"),
    Case("beam", "J", "J = 4.0e-7", "J = 2.0e-7", "frequencies"),
    Case("beam", "Ip", *after(BEAM, "Ip = 9.0e-7"), "frequencies"),
    Case("beam", "y_axis", *after(BEAM, "y_axis = [0.0, 0.6, 0.8]"), "frequencies"),
    Case("beam", "axial", *after(BEAM, "axial = false"), "frequencies"),
    Case("beam", "torsion", *after(BEAM, "torsion = false"), "frequencies"),
    Case("spring", "name", 'name = "mount"', 'name = "mounting"', "check"),
    Case("spring", "ends", 'ends = ["hinge", "cap"]', 'ends = ["tip", "cap"]', "frequencies"),
    Case("spring", "k", "k = [2e6, 3e6, 4e6, 5e4, 6e4, 7e4]", "k = [4e6, 3e6, 4e6, 5e4, 6e4, 7e4]",
         "frequencies"),
    Case("spring", "axes", *after(MOUNT, "axes = [[0.0, 0.6, 0.8], [0.0, 0.8, -0.6], [-1.0, 0.0, 0.0]]"),
         "frequencies"),
    Case("spring", "c", *after(LINK, "c = [50.0, 50.0, 50.0, 1.0, 1.0, 1.0]"), "response"),
    Case("spring", "release", LINK, 'k = [3e6, 4e6, 5e6, 6e4, 7e4, 0.0]\nrelease = ["rz"]', "frequencies"),
    Case("boundary", "free", 'root = "fixed"', 'root = "free"', "frequencies"),
    Case("boundary", "pinned", 'root = "fixed"', 'root = "pinned"', "frequencies"),
    Case("boundary", "fixed", 'root = "fixed"', 'root = "fixed"\ncap = "fixed"', "frequencies"),
    Case("boundary", "list", 'root = "fixed"', 'root = ["x", "y", "z", "rx", "ry"]', "frequencies"),
    Case("damping", "alpha", "[boundary]", "[damping]\nalpha = 2.0\n\n[boundary]", "response"),
    Case("damping", "beta", "[boundary]", "[damping]\nbeta = 1e-4\n\n[boundary]", "response"),
]

def write(tmp_path, text, name="model.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def check_report(path, capsys):
    """The ``linmstmm check --json`` object of the model file ``path``."""
    assert cli.main(["check", str(path), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def response(model):
    """Displacement histories (n_t, points, 6) after an oblique impulse on the
    payload's port, or the message of a ModelError refusing the model."""
    load = PointLoad("cap", np.array([30.0, 40.0, 50.0]), np.array([1.0, 2.0, 3.0]), impulse())
    case = LoadCase((load,), np.linspace(0.0, 0.5, 201), None, MODES)
    try:
        return {"displacement": respond(model, case).displacement}
    except ModelError as error:
        return {"refused": str(error)}


def output(kind, path, capsys):
    """The output ``kind`` of the model file ``path``: named arrays and strings."""
    if kind == "check":
        return {"report": json.dumps(check_report(path, capsys))}
    model = load_model(path)
    if kind == "frequencies":
        return {"hz": natural_frequencies(model, count=MODES).frequencies_hz}
    if kind == "shapes":
        return {"shapes": json.dumps(mode_shapes(model, MODES).to_dict())}
    return response(model)


def differs(before, after):
    """Whether two outputs differ: other names, other text, or numbers moved by
    more than CHANGED of the largest."""
    if before.keys() != after.keys():
        return True
    for key, value in before.items():
        if isinstance(value, str):
            if value != after[key]:
                return True
        elif np.shape(value) != np.shape(after[key]) or (
                np.abs(np.asarray(after[key]) - value).max() > CHANGED * np.abs(value).max()):
            return True
    return False


@pytest.mark.parametrize("case", CASES, ids=str)
def test_key_acts_or_is_refused(tmp_path, capsys, case):
    assert BASE.count(case.old) == 1, case.old
    changed = write(tmp_path, BASE.replace(case.old, case.new))
    if case.output == "refused":
        with pytest.raises(ModelError) as info:
            load_model(changed)
        assert f"'{case.key}'" in str(info.value) and "\n" not in str(info.value), info.value
        return
    before = output(case.output, write(tmp_path, BASE, "base.toml"), capsys)
    now = output(case.output, changed, capsys)
    assert differs(before, now), f"changing {case} left the {case.output} unchanged"
    if "refused" in now:
        assert f"'{case.key}'" in now["refused"], now["refused"]


def test_an_unchanged_model_gives_the_same_outputs(tmp_path, capsys):
    # the comparison itself: the same file twice is no change.
    path = write(tmp_path, BASE)
    for kind in ("check", "frequencies", "shapes", "response"):
        assert not differs(output(kind, path, capsys), output(kind, path, capsys)), kind


def _allowed(tmp_path, text):
    """The keys the loader lists as allowed after an unknown key in ``text``."""
    with pytest.raises(ModelError) as info:
        load_model(write(tmp_path, text))
    return set(re.search(r"allowed keys: (.*)$", str(info.value)).group(1).split(", "))


def test_every_accepted_key_has_a_case(tmp_path):
    unknown = "unknown_key = 1"
    accepted = {
        "top": _allowed(tmp_path, f"{unknown}\n{BASE}"),
        "rigid": _allowed(tmp_path, BASE.replace(PAYLOAD, f"{PAYLOAD}\n{unknown}")),
        "beam": _allowed(tmp_path, BASE.replace(BEAM, f"{BEAM}\n{unknown}")),
        "spring": _allowed(tmp_path, BASE.replace(MOUNT, f"{MOUNT}\n{unknown}")),
        "damping": _allowed(tmp_path, f"{BASE}\n[damping]\n{unknown}\n"),
    }
    with pytest.raises(ModelError) as info:
        load_model(write(tmp_path, BASE.replace('root = "fixed"', 'root = "clamped"')))
    accepted["boundary"] = set(re.findall(r'"(\w+)"', str(info.value))) | {"list"}
    assert "or a list" in str(info.value)
    sections = {"points", "rigid", "beam", "spring", "boundary", "damping"}
    assert sections < accepted["top"]
    covered = {section: {c.key for c in CASES if c.section == section} for section in accepted}
    covered["top"] |= sections
    assert covered == accepted
