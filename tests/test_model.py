"""The model loader (``linmstmm.model.load_model``) against docs/model-format.md.

Error tests start from ``BASE`` (a valid model using every kind of element and
section), change one thing, and check that the ModelError names the file, the
element and the key. CLI tests run ``python -m linmstmm freqs`` on the files in
``tests/data/bad``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from linmstmm.model import Beam, Model, ModelError, Rigid, Spring, load_model

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).resolve().parent / "data"

#: A valid model: a beam "arm" root -> tip, a spring "k1" tip -> hinge (coinciding),
#: a rigid body "payload" on hinge, a vertical beam "post" hinge -> top.
BASE = """\
name = "base"
description = "every kind of element"

[points]
root = [0.0, 0.0, 0.0]
tip = [2.0, 0.0, 0.0]
hinge = [2.0, 0.0, 0.0]
top = [2.0, 0.0, 1.0]

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

[[beam]]
name = "post"
ends = ["hinge", "top"]
E = 7e10
G = 2.6e10
rho = 2700
A = 1e-4
Iy = 1e-8
Iz = 1e-8
J = 2e-8
Ip = 5e-8

[[spring]]
name = "k1"
ends = ["tip", "hinge"]
k = [1e6, 1e6, 1e6, 1e4, 1e4, inf]
c = [1.0, 1.0, 1.0, 0.1, 0.1, 0.0]

[[rigid]]
name = "payload"
ports = ["hinge"]
mass = 5.0
com = [2.0, 0.0, 0.5]
inertia = [0.1, 0.2, 0.3]

[boundary]
root = "fixed"

[damping]
alpha = 0.1
beta = 1e-4
"""


def edit(*pairs, text=BASE):
    """``text`` with each (old, new) replaced; ``old`` must occur exactly once."""
    for old, new in pairs:
        assert text.count(old) == 1, f"{old!r} occurs {text.count(old)} times"
        text = text.replace(old, new)
    return text


def write(tmp_path, text, name="model.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def load_text(tmp_path, text):
    return load_model(write(tmp_path, text))


def model_error(tmp_path, text, element, key, *words):
    """The ModelError of ``text``, checked to name file, element, key and ``words``."""
    path = write(tmp_path, text)
    with pytest.raises(ModelError) as info:
        load_model(path)
    error = info.value
    line = str(error)
    assert error.file == str(path) and line.startswith(str(path))
    assert (error.element, error.key) == (element, key), line
    if element is not None:
        assert element in line
    if key is not None:
        assert f"key '{key}'" in line
    for word in words:
        assert word in line, line
    assert "\n" not in line
    return error


def test_base_model_is_valid(tmp_path):
    model = load_text(tmp_path, BASE)
    assert isinstance(model, Model)
    assert [e.name for e in model.elements] == ["payload", "arm", "post", "k1"]


# --- reading ------------------------------------------------------------------

def test_missing_file(tmp_path):
    path = tmp_path / "absent.toml"
    with pytest.raises(ModelError, match="absent.toml: cannot read"):
        load_model(path)


def test_directory_is_unreadable(tmp_path):
    with pytest.raises(ModelError, match="cannot read"):
        load_model(tmp_path)


def test_syntax_error_names_line_and_column(tmp_path):
    line = BASE.splitlines().index("mass = 5.0") + 1
    model_error(tmp_path, edit(("mass = 5.0", "mass = 5.0.0")), None, None,
                "invalid TOML", f"line {line}, column ")


def test_duplicate_point_name(tmp_path):
    text = edit(("top = [2.0, 0.0, 1.0]\n", "top = [2.0, 0.0, 1.0]\ntop = [3.0, 0.0, 1.0]\n"))
    model_error(tmp_path, text, None, None, "invalid TOML", "line 9", "duplicate point name")


@pytest.mark.parametrize("opening, closing", [("[", "]"), ("{a = ", "}")])
def test_nesting_too_deep_for_the_reader(tmp_path, opening, closing):
    depth = 5000
    text = edit(('name = "base"', f'name = "base"\nx = {opening * depth}1{closing * depth}'))
    model_error(tmp_path, text, None, None, "invalid TOML", "nested too deeply")


def test_not_utf8(tmp_path):
    path = tmp_path / "model.toml"
    path.write_bytes(BASE.encode().replace(b'"base"', b'"b\xffse"'))
    with pytest.raises(ModelError, match="not UTF-8"):
        load_model(path)


# --- keys and types -----------------------------------------------------------

@pytest.mark.parametrize("text, element, key", [
    (edit(("mass = 5.0\n", "")), "rigid 'payload'", "mass"),
    (edit(('name = "base"\n', "")), None, "name"),
    (edit(("Iz = 3.0e-7\n", "")), "beam 'arm'", "Iz"),
    (edit(('ends = ["tip", "hinge"]\n', "")), "spring 'k1'", "ends"),
    (edit(("[points]\nroot = [0.0, 0.0, 0.0]\ntip = [2.0, 0.0, 0.0]\n"
           "hinge = [2.0, 0.0, 0.0]\ntop = [2.0, 0.0, 1.0]\n", "")), None, "points"),
])
def test_missing_required_key(tmp_path, text, element, key):
    model_error(tmp_path, text, element, key, "missing required key")


def test_element_without_name_is_labelled_by_position(tmp_path):
    model_error(tmp_path, edit(('name = "k1"\n', "")), "spring #1", "name", "missing")


@pytest.mark.parametrize("old, new, element, key, words", [
    ("E = 2.1e11", 'E = "2.1e11"', "beam 'arm'", "E", ["must be a number", "string '2.1e11'"]),
    ("mass = 5.0", "mass = true", "rigid 'payload'", "mass", ["must be a number", "boolean true"]),
    ("com = [2.0, 0.0, 0.5]", "com = [2.0, 0.0]", "rigid 'payload'", "com",
     ["array of 3 numbers", "length 2"]),
    ("com = [2.0, 0.0, 0.5]", "com = [2.0, false, 0.5]", "rigid 'payload'", "com", ["com[1]"]),
    ("k = [1e6, 1e6, 1e6, 1e4, 1e4, inf]", "k = [1e6, 1e6, 1e6]", "spring 'k1'", "k",
     ["array of 6 numbers"]),
    ("top = [2.0, 0.0, 1.0]", 'top = "up"', "[points]", "top", ["array of 3 numbers"]),
    ('name = "arm"', "name = 7", "beam #1", "name", ["must be a non-empty string"]),
    ('name = "base"', 'name = ""', None, "name", ["non-empty string"]),
    ('ports = ["hinge"]', 'ports = "hinge"', "rigid 'payload'", "ports", ["array of point names"]),
    ('ends = ["root", "tip"]', 'ends = ["root", "tip", "top"]', "beam 'arm'", "ends",
     ["array of 2 point names"]),
    ('ends = ["root", "tip"]', 'ends = ["root", 1]', "beam 'arm'", "ends", ["ends[1]"]),
    ("Ip = 5e-8", "Ip = 5e-8\naxial = 1", "beam 'post'", "axial", ["true or false"]),
    ("Ip = 5e-8", 'Ip = 5e-8\ntorsion = "no"', "beam 'post'", "torsion", ["true or false"]),
    ("inertia = [0.1, 0.2, 0.3]", "inertia = [[0.1, 0.0], [0.0, 0.2]]", "rigid 'payload'",
     "inertia", ["3x3"]),
    ('description = "every kind of element"', "description = 3", None, "description",
     ["must be a string"]),
])
def test_wrong_type(tmp_path, old, new, element, key, words):
    model_error(tmp_path, edit((old, new)), element, key, *words)


def test_section_of_wrong_kind(tmp_path):
    text = edit(("[[spring]]", "[spring]"), ("[[rigid]]", "[rigid]"))
    model_error(tmp_path, text, None, "rigid", "array of tables [[rigid]]")


def test_unknown_key_is_named_with_suggestion_and_allowed_keys(tmp_path):
    model_error(tmp_path, edit(("mass = 5.0", "mas = 5.0")), "rigid 'payload'", "mas",
                "unknown key", "did you mean 'mass'?", "allowed keys: name, ports, mass, com, inertia")


@pytest.mark.parametrize("old, new, element, key", [
    ("Iz = 3.0e-7", "Iz = 3.0e-7\nIx = 1.0", "beam 'arm'", "Ix"),
    ("c = [", "C = [", "spring 'k1'", "C"),
    ('name = "base"', 'name = "base"\nversion = 2', None, "version"),
    ("beta = 1e-4", "gamma = 1e-4", "[damping]", "gamma"),
])
def test_unknown_key(tmp_path, old, new, element, key):
    model_error(tmp_path, edit((old, new)), element, key, "unknown key", "allowed keys")


# --- values -------------------------------------------------------------------

@pytest.mark.parametrize("k, index", [("0.0", 2), ("-1e6", 2), ("-inf", 2)])
def test_non_positive_stiffness(tmp_path, k, index):
    text = edit(("k = [1e6, 1e6, 1e6,", f"k = [1e6, 1e6, {k},"))
    model_error(tmp_path, text, "spring 'k1'", "k", f"k[{index}] must be > 0")


def test_infinite_stiffness_is_rigid_and_allowed(tmp_path):
    text = edit(("k = [1e6, 1e6, 1e6, 1e4, 1e4, inf]", "k = [inf, inf, inf, 1e4, 1e4, inf]"))
    spring = load_text(tmp_path, text).element("k1")
    assert np.isinf(spring.k[[0, 1, 2, 5]]).all() and spring.k[3] == 1e4


def test_negative_damping_c(tmp_path):
    text = edit(("c = [1.0, 1.0, 1.0, 0.1, 0.1, 0.0]", "c = [1.0, 1.0, 1.0, 0.1, -0.1, 0.0]"))
    model_error(tmp_path, text, "spring 'k1'", "c", "c[4] must be >= 0")


@pytest.mark.parametrize("old, new, element, key, label", [
    ("top = [2.0, 0.0, 1.0]", "top = [2.0, nan, 1.0]", "[points]", "top", "top[1]"),
    ("top = [2.0, 0.0, 1.0]", "top = [2.0, 0.0, inf]", "[points]", "top", "top[2]"),
    ("E = 2.1e11", "E = inf", "beam 'arm'", "E", "E"),
    ("mass = 5.0", "mass = nan", "rigid 'payload'", "mass", "mass"),
    ("k = [1e6,", "k = [nan,", "spring 'k1'", "k", "k[0]"),
    ("c = [1.0,", "c = [inf,", "spring 'k1'", "c", "c[0]"),
    ("alpha = 0.1", "alpha = inf", "[damping]", "alpha", "alpha"),
])
def test_non_finite_values(tmp_path, old, new, element, key, label):
    model_error(tmp_path, edit((old, new)), element, key, f"{label} must be finite")


def test_spring_ends_must_coincide(tmp_path):
    text = edit(("hinge = [2.0, 0.0, 0.0]", "hinge = [2.001, 0.0, 0.0]"))
    model_error(tmp_path, text, "spring 'k1'", "ends", "'tip' and 'hinge' do not coincide")


def test_spring_ends_within_tolerance_coincide(tmp_path):
    # model size ~2.2 m: 1e-12 m is far inside 1e-9 relative.
    text = edit(("hinge = [2.0, 0.0, 0.0]", "hinge = [2.000000000001, 0.0, 0.0]"))
    assert load_text(tmp_path, text).element("k1").ends == ("tip", "hinge")


def test_spring_with_both_ends_on_one_point(tmp_path):
    text = edit(('ends = ["tip", "hinge"]', 'ends = ["hinge", "hinge"]'))
    model_error(tmp_path, text, "spring 'k1'", "ends", "both ends are point 'hinge'")


def test_beam_of_zero_length_between_coinciding_points(tmp_path):
    # tip and hinge are distinct points at the same place.
    text = edit(('ends = ["root", "tip"]', 'ends = ["tip", "hinge"]'))
    model_error(tmp_path, text, "beam 'arm'", "ends", "zero length")


def test_beam_with_both_ends_on_one_point(tmp_path):
    text = edit(('ends = ["root", "tip"]', 'ends = ["tip", "tip"]'))
    model_error(tmp_path, text, "beam 'arm'", "ends", "zero length", "'tip'")


@pytest.mark.parametrize("old, new, element, key", [
    ('ports = ["hinge"]', 'ports = ["hnige"]', "rigid 'payload'", "ports"),
    ('ends = ["root", "tip"]', 'ends = ["root", "hnige"]', "beam 'arm'", "ends"),
    ('ends = ["tip", "hinge"]', 'ends = ["tip", "hnige"]', "spring 'k1'", "ends"),
    ('root = "fixed"', 'hnige = "fixed"', "[boundary]", "hnige"),
])
def test_unknown_point(tmp_path, old, new, element, key):
    model_error(tmp_path, edit((old, new)), element, key, "unknown point 'hnige'",
                "did you mean 'hinge'?")


@pytest.mark.parametrize("old, new, element", [
    ('name = "k1"', 'name = "arm"', "spring 'arm'"),
    ('name = "payload"', 'name = "post"', "beam 'post'"),
    ('name = "post"', 'name = "arm"', "beam 'arm'"),
])
def test_duplicate_element_name(tmp_path, old, new, element):
    error = model_error(tmp_path, edit((old, new)), element, "name", "duplicate element name")
    assert "already used by" in str(error)


def test_inertia_not_symmetric(tmp_path):
    text = edit(("inertia = [0.1, 0.2, 0.3]",
                 "inertia = [[0.1, 0.01, 0.0], [0.02, 0.2, 0.0], [0.0, 0.0, 0.3]]"))
    model_error(tmp_path, text, "rigid 'payload'", "inertia", "not symmetric",
                "inertia[0][1]", "inertia[1][0]")


def test_inertia_not_positive_semidefinite(tmp_path):
    text = edit(("inertia = [0.1, 0.2, 0.3]",
                 "inertia = [[0.1, 0.5, 0.0], [0.5, 0.2, 0.0], [0.0, 0.0, 0.3]]"))
    model_error(tmp_path, text, "rigid 'payload'", "inertia", "not positive semidefinite")


def test_inertia_diagonal_with_negative_entry(tmp_path):
    text = edit(("inertia = [0.1, 0.2, 0.3]", "inertia = [0.1, -0.2, 0.3]"))
    model_error(tmp_path, text, "rigid 'payload'", "inertia", "inertia[1] must be >= 0")


@pytest.mark.parametrize("inertia", [
    "[0.1, 0.2, 0.5]",                                              # Izz > Ixx + Iyy
    "[0.5, 0.1, 0.2]",                                              # Ixx > Iyy + Izz
    "[[0.3, 0.2, 0.0], [0.2, 0.3, 0.0], [0.0, 0.0, 0.05]]",         # principal 0.05, 0.1, 0.5
])
def test_inertia_breaking_the_triangle_inequality(tmp_path, inertia):
    text = edit(("inertia = [0.1, 0.2, 0.3]", f"inertia = {inertia}"))
    model_error(tmp_path, text, "rigid 'payload'", "inertia", "triangle inequality", "no real body")


def _rotated_plate(scale):
    """Inertia tensor, kg m^2 x ``scale``, of a flat plate (Izz = Ixx + Iyy) turned about
    an oblique axis: the equality holds only to rounding."""
    angle, axis = 0.7, np.array([1.0, 2.0, 2.0]) / 3.0
    cross = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rotation = np.eye(3) + math.sin(angle) * cross + (1 - math.cos(angle)) * cross @ cross
    return scale * rotation @ np.diag([0.1, 0.25, 0.35]) @ rotation.T


@pytest.mark.parametrize("scale", [1.0, 1e-6, 1e6])
@pytest.mark.parametrize("principal", [[0.0, 0.0, 0.0], [0.0, 0.2, 0.2], [0.2, 0.2, 0.4], None])
def test_inertia_on_the_triangle_boundary_is_accepted(tmp_path, principal, scale):
    # point mass, thin rod, flat plates (None: turned): equality, in any units of mass and length.
    tensor = _rotated_plate(scale) if principal is None else scale * np.diag(principal)
    text = edit(("inertia = [0.1, 0.2, 0.3]", f"inertia = {tensor.tolist()}"))
    np.testing.assert_allclose(load_text(tmp_path, text).element("payload").inertia, tensor, rtol=1e-15)


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_triangle_check_does_not_depend_on_units(tmp_path, scale):
    # a plate whose Izz exceeds Ixx + Iyy by 1e-6 of the trace is refused at every scale.
    tensor = _rotated_plate(scale) + scale * 1e-6 * 0.7 * np.diag([0.0, 0.0, 1.0])
    text = edit(("inertia = [0.1, 0.2, 0.3]", f"inertia = {tensor.tolist()}"))
    model_error(tmp_path, text, "rigid 'payload'", "inertia", "triangle inequality")


def test_negative_mass(tmp_path):
    model_error(tmp_path, edit(("mass = 5.0", "mass = -5.0")), "rigid 'payload'", "mass",
                "must be >= 0")


def test_model_without_mass(tmp_path):
    text = edit(("mass = 5.0", "mass = 0"), ("rho = 7850.0", "rho = 0.0"), ("rho = 2700", "rho = 0"))
    error = model_error(tmp_path, text, None, None, "no mass")
    assert error.message.startswith("model has no mass")


def test_massless_beam_is_allowed(tmp_path):
    model = load_text(tmp_path, edit(("rho = 7850.0", "rho = 0")))
    assert model.element("arm").rho == 0.0 and model.element("arm").mass == 0.0


#: The lines of beam 'post' that set its section constants.
POST_LINES = {"E": "E = 7e10", "G": "G = 2.6e10", "A": "A = 1e-4", "Iy": "Iy = 1e-8",
              "Iz": "Iz = 1e-8", "J": "J = 2e-8", "Ip": "Ip = 5e-8"}


@pytest.mark.parametrize("key", POST_LINES)
@pytest.mark.parametrize("value", ["0.0", "-1.0"])
def test_beam_section_constants_must_be_positive(tmp_path, key, value):
    text = edit((POST_LINES[key], f"{key} = {value}"))
    model_error(tmp_path, text, "beam 'post'", key, f"{key} must be > 0")


def test_negative_density(tmp_path):
    model_error(tmp_path, edit(("rho = 7850.0", "rho = -1.0")), "beam 'arm'", "rho", "must be >= 0")


def test_point_not_used_by_any_element(tmp_path):
    text = edit(("top = [2.0, 0.0, 1.0]", "top = [2.0, 0.0, 1.0]\nspare = [9.0, 9.0, 9.0]"))
    model_error(tmp_path, text, "[points]", "spare", "not used by any element")


def test_point_used_only_by_boundary_is_unused(tmp_path):
    text = edit(("top = [2.0, 0.0, 1.0]", "top = [2.0, 0.0, 1.0]\nspare = [9.0, 9.0, 9.0]"),
                ('root = "fixed"', 'root = "fixed"\nspare = "pinned"'))
    model_error(tmp_path, text, "[points]", "spare", "not used")


def test_rigid_without_ports(tmp_path):
    model_error(tmp_path, edit(('ports = ["hinge"]', "ports = []")), "rigid 'payload'", "ports",
                "non-empty array of point names")


def test_rigid_with_repeated_port(tmp_path):
    model_error(tmp_path, edit(('ports = ["hinge"]', 'ports = ["hinge", "hinge"]')),
                "rigid 'payload'", "ports", "'hinge' is listed twice")


@pytest.mark.parametrize("axes, words", [
    ("[[1, 0, 0], [0, 1, 0], [0, 0, -1]]", "right-handed"),
    ("[[1, 0, 0], [0, 2, 0], [0, 0, 1]]", "orthonormal"),
    ("[[1, 0, 0], [1, 0, 0], [0, 0, 1]]", "orthonormal"),
    ("[[1, 0, 0], [0, 1, 0]]", "3x3"),
    ('[[1, 0, 0], [0, 1, 0], [0, 0, "1"]]', "axes[2][2] must be a number"),
])
def test_spring_axes_must_be_a_rotation(tmp_path, axes, words):
    text = edit(("k = [", f"axes = {axes}\nk = ["))
    model_error(tmp_path, text, "spring 'k1'", "axes", words)


@pytest.mark.parametrize("y_axis", ["[0, 0, 5]", "[0, 0, -1]", "[0, 0, 0]"])
def test_beam_y_axis_parallel_to_beam(tmp_path, y_axis):
    text = edit(("Ip = 5e-8", f"Ip = 5e-8\ny_axis = {y_axis}"))
    model_error(tmp_path, text, "beam 'post'", "y_axis", "parallel to the beam axis")


@pytest.mark.parametrize("value, words", [
    ('"clamped"', "unknown condition 'clamped'"),
    ('["x", "w"]', "root[1] = string 'w' is not one of x, y, z, rx, ry, rz"),
    ('["x", "rz", "x"]', "component 'x' is listed twice"),
    ("[1, 2]", "root[0] = 1 is not one of"),
    ("6", "got 6"),
])
def test_bad_boundary_value(tmp_path, value, words):
    model_error(tmp_path, edit(('root = "fixed"', f"root = {value}")), "[boundary]", "root", words)


@pytest.mark.parametrize("old, new, key, words", [
    ("alpha = 0.1", "alpha = -0.1", "alpha", "must be >= 0"),
    ("beta = 1e-4", 'beta = "small"', "beta", "must be a number"),
    ("beta = 1e-4", "beta = false", "beta", "must be a number"),
    ("beta = 1e-4", "delta = 1e-4", "delta", "allowed keys: alpha, beta"),
])
def test_bad_damping(tmp_path, old, new, key, words):
    model_error(tmp_path, edit((old, new)), "[damping]", key, words)


# --- building -----------------------------------------------------------------

def test_spec_cantilever_example():
    path = DATA / "good" / "cantilever.toml"
    model = load_model(path)
    assert model.name == "cantilever with tip mass" and model.description == ""
    assert model.source == str(path)
    assert list(model.points) == ["root", "tip"]
    np.testing.assert_array_equal(model.points["tip"], [2.0, 0.0, 0.0])
    (arm,) = model.beams
    assert isinstance(arm, Beam) and arm.ends == ("root", "tip")
    assert (arm.E, arm.G, arm.rho, arm.A) == (2.1e11, 8.1e10, 7850.0, 1.0e-3)
    assert arm.length == 2.0 and arm.Ip == pytest.approx(4.0e-7)
    assert math.isclose(arm.mass, 7850.0 * 1.0e-3 * 2.0)
    assert arm.axial and arm.torsion
    np.testing.assert_array_equal(arm.axes, np.eye(3))
    (payload,) = model.rigids
    assert isinstance(payload, Rigid) and payload.ports == ("tip",) and payload.mass == 5.0
    np.testing.assert_array_equal(payload.inertia, np.zeros((3, 3)))
    assert model.springs == ()
    assert model.fixed_mask("root").all() and not model.fixed_mask("tip").any()
    assert list(model.boundary) == ["root"]
    assert model.damping is None


def test_derived_values_of_base_model(tmp_path):
    model = load_text(tmp_path, BASE)
    assert model.description == "every kind of element"
    post = model.element("post")
    assert post.Ip == 5e-8 and post.rho == 2700.0 and isinstance(post.rho, float)
    assert model.element("arm").Ip == pytest.approx(5e-7)
    spring = model.element("k1")
    assert isinstance(spring, Spring) and spring.ends == ("tip", "hinge")
    np.testing.assert_array_equal(spring.axes, np.eye(3))
    np.testing.assert_array_equal(spring.c, [1.0, 1.0, 1.0, 0.1, 0.1, 0.0])
    assert spring.k.shape == (6,) and spring.k.dtype == float and np.isinf(spring.k[5])
    np.testing.assert_array_equal(model.element("payload").inertia, np.diag([0.1, 0.2, 0.3]))
    assert model.damping == (0.1, 1e-4)


def test_optional_spring_fields(tmp_path):
    axes = "[[0, 1, 0], [-1, 0, 0], [0, 0, 1]]"
    text = edit(("c = [1.0, 1.0, 1.0, 0.1, 0.1, 0.0]\n", f"axes = {axes}\n"))
    spring = load_text(tmp_path, text).element("k1")
    assert spring.c is None
    np.testing.assert_array_equal(spring.axes, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]])


def test_integers_are_accepted_for_floats(tmp_path):
    model = load_text(tmp_path, edit(("mass = 5.0", "mass = 5"), ("hinge = [2.0, 0.0, 0.0]",
                                                                  "hinge = [2, 0, 0]")))
    assert model.element("payload").mass == 5.0 and isinstance(model.element("payload").mass, float)
    assert model.points["hinge"].dtype == float


def test_full_inertia_tensor(tmp_path):
    tensor = [[2.0, -0.5, 0.1], [-0.5, 3.0, 0.0], [0.1, 0.0, 4.0]]
    text = edit(("inertia = [0.1, 0.2, 0.3]", f"inertia = {tensor}"))
    inertia = load_text(tmp_path, text).element("payload").inertia
    assert inertia.shape == (3, 3)
    np.testing.assert_array_equal(inertia, tensor)


def _beam_axes(tmp_path, top, extra=""):
    """Axes of beam 'post' from hinge (2, 0, 0) to ``top``."""
    text = edit(("top = [2.0, 0.0, 1.0]", f"top = {top}"), ("Ip = 5e-8", f"Ip = 5e-8\n{extra}"))
    axes = load_text(tmp_path, text).element("post").axes
    np.testing.assert_allclose(axes @ axes.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(axes) == pytest.approx(1.0)
    return axes


@pytest.mark.parametrize("top, expected", [
    ("[2.0, 0.0, 1.0]", [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]),   # up: y = e_Y
    ("[2.0, 0.0, -3.0]", [[0, 0, -1], [0, 1, 0], [1, 0, 0]]),  # down: y = e_Y
    ("[5.0, 0.0, 0.0]", [[1, 0, 0], [0, 1, 0], [0, 0, 1]]),    # along X
    ("[2.0, 1.0, 0.0]", [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]),   # along Y: y = e_Z x e_Y = -e_X
])
def test_beam_default_axes(tmp_path, top, expected):
    np.testing.assert_allclose(_beam_axes(tmp_path, top), expected, atol=1e-15)


def test_beam_default_axes_oblique(tmp_path):
    axes = _beam_axes(tmp_path, "[3.0, 1.0, 1.0]")
    x = np.array([1.0, 1.0, 1.0]) / np.sqrt(3)
    y = np.cross([0, 0, 1], x) / np.linalg.norm(np.cross([0, 0, 1], x))
    np.testing.assert_allclose(axes, [x, y, np.cross(x, y)], atol=1e-15)


def test_beam_y_axis_is_projected_and_normalised(tmp_path):
    axes = _beam_axes(tmp_path, "[2.0, 0.0, 1.0]", "y_axis = [3.0, 0.0, 7.0]")
    np.testing.assert_allclose(axes, [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)


@pytest.mark.parametrize("top, y_axis", [("[2.0, 0.0, 1.0]", None), ("[2.0, 0.0, -3.0]", None),
                                         ("[3.0, 1.0, 1.0]", None), ("[2.0, 1.0, 0.0]", None),
                                         ("[3.0, -2.0, 0.5]", None), ("[2.0, 0.0, 1.0]", [3.0, 0.0, 7.0])])
def test_builders_and_scenes_frame_beams_as_the_loader_does(tmp_path, top, y_axis):
    """One rule for a beam's local axes (linmstmm.geometry.local_axes): the loader's, the
    builders' and the launcher scenes' tube frame agree with each other."""
    from linmstmm.builders import beam_axes
    from linmstmm.scenes import tube_frame

    extra = "" if y_axis is None else f"y_axis = {y_axis}"
    loaded = _beam_axes(tmp_path, top, extra)
    end = np.array(json.loads(top))
    np.testing.assert_allclose(beam_axes([2.0, 0.0, 0.0], end, y_axis), loaded, atol=1e-15)
    if y_axis is None and end[0] != 2.0:  # not vertical: a tube's frame is a beam's default one
        np.testing.assert_allclose(tube_frame(end - [2.0, 0.0, 0.0]), loaded, atol=1e-15)


@pytest.mark.parametrize("hint", [[0.0, 0.0, 0.0], [0.0, 0.0, -2.0], [1e-12, 0.0, 1.0]])
def test_builders_refuse_a_y_hint_along_the_beam(hint):
    """A builder's zero or parallel y hint is refused, as a file's y_axis is (it was
    replaced by e_Y without a word)."""
    from linmstmm.builders import beam_axes

    with pytest.raises(ValueError, match="zero or parallel to the beam axis"):
        beam_axes([2.0, 0.0, 0.0], [2.0, 0.0, 1.0], hint)


def test_beam_rigidity_flags(tmp_path):
    post = load_text(tmp_path, edit(("Ip = 5e-8", "Ip = 5e-8\naxial = false\ntorsion = false")))
    assert post.element("post").axial is False and post.element("post").torsion is False


@pytest.mark.parametrize("value, mask", [
    ('"fixed"', [1, 1, 1, 1, 1, 1]),
    ('"pinned"', [1, 1, 1, 0, 0, 0]),
    ('["y", "rz"]', [0, 1, 0, 0, 0, 1]),
    ('["rx", "z"]', [0, 0, 1, 1, 0, 0]),
])
def test_boundary_masks(tmp_path, value, mask):
    model = load_text(tmp_path, edit(('root = "fixed"', f'root = {value}\ntop = "free"')))
    assert model.boundary["root"].dtype == bool
    np.testing.assert_array_equal(model.boundary["root"], np.array(mask, dtype=bool))
    assert "top" not in model.boundary and not model.fixed_mask("top").any()


def test_damping_defaults(tmp_path):
    assert load_text(tmp_path, edit(("beta = 1e-4\n", ""))).damping == (0.1, 0.0)
    assert load_text(tmp_path, edit(("[damping]\nalpha = 0.1\nbeta = 1e-4\n", ""))).damping is None


def test_elements_keep_file_order(tmp_path):
    model = load_text(tmp_path, BASE)
    assert [b.name for b in model.beams] == ["arm", "post"]


def test_records_are_immutable(tmp_path):
    model = load_text(tmp_path, BASE)
    spring, payload, post = model.element("k1"), model.element("payload"), model.element("post")
    arrays = [spring.k, spring.axes, spring.c, payload.com, payload.inertia, post.axes,
              model.points["tip"], model.boundary["root"]]
    for array in arrays:
        with pytest.raises(ValueError):
            array[0] = 0
    with pytest.raises(AttributeError):
        payload.mass = 1.0


# --- command line -------------------------------------------------------------

@pytest.mark.parametrize("name, words", [
    ("unknown_key.toml", ["rigid 'payload'", "key 'mas'", "unknown key"]),
    ("spring_gap.toml", ["spring 'k1'", "key 'ends'", "do not coincide"]),
    ("negative_stiffness.toml", ["spring 'k1'", "key 'k'", "k[2] must be > 0"]),
    ("syntax_error.toml", ["invalid TOML", "line 5"]),
    ("missing.toml", ["cannot read"]),
])
def test_cli_reports_bad_model_in_one_line(name, words):
    relative = f"tests/data/bad/{name}"
    done = subprocess.run([sys.executable, "-m", "linmstmm", "freqs", relative],
                          cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""
    for word in [relative, *words]:
        assert word in lines[0]


# --- models built in code -----------------------------------------------------
#
# Model(...) runs the loader's checks on its records: each case below changes
# one record of the base model in code and expects the loader's message, with
# "model 'base'" (the model's name) in place of the file.

@pytest.fixture
def base(tmp_path):
    """BASE as a Model built in code (no source file)."""
    return dataclasses.replace(load_text(tmp_path, BASE), source=None)


def changed(model, element, **values):
    """``model`` rebuilt (so checked) with ``values`` set on the record ``element``."""
    attribute = {"rigid": "rigids", "beam": "beams", "spring": "springs"}[model.element(element).kind]
    records = tuple(dataclasses.replace(r, **values) if r.name == element else r
                    for r in getattr(model, attribute))
    return dataclasses.replace(model, **{attribute: records})


def with_points(model, **points):
    return dataclasses.replace(model, points=model.points | {p: np.array(v) for p, v in points.items()})


def code_error(build, model, element, key, *words):
    """The ModelError of ``build(model)``, checked as :func:`model_error` checks a file's."""
    with pytest.raises(ModelError) as info:
        build(model)
    error, line = info.value, str(info.value)
    assert error.file in ("model 'base'", "model ''") and line.startswith(error.file + ": "), line
    assert (error.element, error.key) == (element, key), line
    for word in words:
        assert word in line, line
    return error


PLATE_OFF_AXIS = np.diag([0.1, 0.2, 0.5])
UNSYMMETRIC = np.array([[0.1, 0.01, 0.0], [0.02, 0.2, 0.0], [0.0, 0.0, 0.3]])
NOT_PSD = np.array([[0.1, 0.5, 0.0], [0.5, 0.2, 0.0], [0.0, 0.0, 0.3]])
FLIPPED = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, -1.0]])


@pytest.mark.parametrize("build, element, key, words", [
    (lambda m: dataclasses.replace(m, name=""), None, "name", ["non-empty string"]),
    (lambda m: dataclasses.replace(m, description=3), None, "description", ["must be a string"]),
    (lambda m: dataclasses.replace(m, points=[]), None, "points", ["must be a table [points]"]),
    (lambda m: with_points(m, top=[2.0, np.nan, 1.0]), "[points]", "top", ["top[1] must be finite"]),
    (lambda m: with_points(m, top=[2.0, 1.0]), "[points]", "top", ["array of 3 numbers"]),
    (lambda m: with_points(m, spare=[9.0, 9.0, 9.0]), "[points]", "spare", ["not used by any element"]),
    (lambda m: changed(m, "payload", name=""), "rigid #1", "name", ["non-empty string"]),
    (lambda m: changed(m, "k1", name="arm"), "spring 'arm'", "name", ["duplicate element name"]),
    (lambda m: changed(m, "payload", ports=()), "rigid 'payload'", "ports", ["non-empty array"]),
    (lambda m: changed(m, "payload", ports=("hnige",)), "rigid 'payload'", "ports",
     ["unknown point 'hnige'", "did you mean 'hinge'?"]),
    (lambda m: changed(m, "payload", ports=("hinge", "hinge")), "rigid 'payload'", "ports", ["listed twice"]),
    (lambda m: changed(m, "payload", mass=-5.0), "rigid 'payload'", "mass", ["mass must be >= 0"]),
    (lambda m: changed(m, "payload", mass=np.inf), "rigid 'payload'", "mass", ["mass must be finite"]),
    (lambda m: changed(m, "payload", com=np.zeros(2)), "rigid 'payload'", "com", ["array of 3 numbers"]),
    (lambda m: changed(m, "payload", inertia=np.zeros(3)), "rigid 'payload'", "inertia",
     ["(3, 3) tensor"]),
    (lambda m: changed(m, "payload", inertia=np.zeros((3, 2))), "rigid 'payload'", "inertia", ["3x3"]),
    (lambda m: changed(m, "payload", inertia=UNSYMMETRIC), "rigid 'payload'", "inertia", ["not symmetric"]),
    (lambda m: changed(m, "payload", inertia=NOT_PSD), "rigid 'payload'", "inertia",
     ["not positive semidefinite"]),
    (lambda m: changed(m, "payload", inertia=PLATE_OFF_AXIS), "rigid 'payload'", "inertia",
     ["triangle inequality"]),
    (lambda m: changed(m, "arm", ends=("root",)), "beam 'arm'", "ends", ["array of 2 point names"]),
    (lambda m: changed(m, "arm", ends=("tip", "tip")), "beam 'arm'", "ends", ["zero length"]),
    (lambda m: changed(m, "arm", ends=("tip", "hinge")), "beam 'arm'", "ends", ["zero length", "coincide"]),
    (lambda m: changed(m, "arm", ends=("root", "hnige")), "beam 'arm'", "ends", ["unknown point 'hnige'"]),
    (lambda m: changed(m, "arm", rho=-1.0), "beam 'arm'", "rho", ["rho must be >= 0"]),
    (lambda m: changed(m, "arm", axial=1), "beam 'arm'", "axial", ["true or false"]),
    (lambda m: changed(m, "arm", torsion="no"), "beam 'arm'", "torsion", ["true or false"]),
    (lambda m: changed(m, "arm", length=2.5), "beam 'arm'", "length",
     ["distance between the ends, 2 m", "got 2.5"]),
    (lambda m: changed(m, "arm", axes=-np.eye(3)), "beam 'arm'", "axes", ["local x"]),
    (lambda m: changed(m, "arm", axes=np.diag([1.0, 1.0, -1.0])), "beam 'arm'", "axes", ["right-handed"]),
    (lambda m: changed(m, "arm", axes=np.eye(2)), "beam 'arm'", "axes", ["local x"]),
    (lambda m: changed(m, "arm", axes=1.0), "beam 'arm'", "axes", ["local x"]),
    (lambda m: changed(m, "arm", length=np.nan), "beam 'arm'", "length", ["2 m", "got nan"]),
    (lambda m: changed(m, "arm", length=np.array(2.5)), "beam 'arm'", "length", ["2 m", "got array(2.5)"]),
    (lambda m: changed(m, "arm", axes=np.array([[1.0, 0, 0], [1.0, 0, 0], [0, 0, 1.0]])), "beam 'arm'",
     "y_axis", ["parallel to the beam axis"]),
    (lambda m: with_points(m, hinge=[2.001, 0.0, 0.0]), "spring 'k1'", "ends", ["do not coincide"]),
    (lambda m: changed(m, "k1", k=np.array([1e6, 1e6, 0.0, 1e4, 1e4, np.inf])), "spring 'k1'", "k",
     ["k[2] must be > 0"]),
    (lambda m: changed(m, "k1", k=np.ones(3)), "spring 'k1'", "k", ["array of 6 numbers"]),
    (lambda m: changed(m, "k1", axes=FLIPPED), "spring 'k1'", "axes", ["right-handed"]),
    (lambda m: changed(m, "k1", axes=2 * np.eye(3)), "spring 'k1'", "axes", ["orthonormal"]),
    (lambda m: changed(m, "k1", c=-np.ones(6)), "spring 'k1'", "c", ["c[0] must be >= 0"]),
    (lambda m: dataclasses.replace(m, boundary={"hnige": np.ones(6, bool)}), "[boundary]", "hnige",
     ["unknown point 'hnige'"]),
    (lambda m: dataclasses.replace(m, boundary={"root": np.ones(3, bool)}), "[boundary]", "root",
     ["(6,) bool mask"]),
    (lambda m: dataclasses.replace(m, boundary={"root": np.ones(6)}), "[boundary]", "root", ["(6,) bool mask"]),
    (lambda m: dataclasses.replace(m, damping=(-0.1, 0.0)), "[damping]", "alpha", ["alpha must be >= 0"]),
    (lambda m: dataclasses.replace(m, damping=(0.1, np.nan)), "[damping]", "beta", ["beta must be finite"]),
    (lambda m: dataclasses.replace(m, damping=0.1), None, "damping", ["(alpha, beta)"]),
    (lambda m: dataclasses.replace(m, rigids=m.beams[:1]), None, None, ["rigids[0] must be a Rigid record"]),
])
def test_model_built_in_code_is_checked(base, build, element, key, words):
    code_error(build, base, element, key, *words)


@pytest.mark.parametrize("key", ["E", "G", "A", "Iy", "Iz", "J", "Ip"])
def test_beam_constants_built_in_code_must_be_positive(base, key):
    code_error(lambda m: changed(m, "post", **{key: 0.0}), base, "beam 'post'", key, f"{key} must be > 0")


def test_model_without_mass_built_in_code(base):
    code_error(lambda m: changed(changed(changed(m, "payload", mass=0.0), "arm", rho=0.0), "post", rho=0.0),
               base, None, None, "model has no mass")


def test_model_without_elements_built_in_code():
    for points in ({}, {"a": np.zeros(3)}):
        with pytest.raises(ModelError, match="^model 'empty': model has no elements"):
            Model("empty", points)


def test_code_and_file_get_the_same_message(tmp_path, base):
    from_file = model_error(tmp_path, edit(("mass = 5.0", "mass = -5.0")), "rigid 'payload'", "mass")
    from_code = code_error(lambda m: changed(m, "payload", mass=-5.0), base, "rigid 'payload'", "mass")
    assert from_code.message == from_file.message


def test_model_built_in_code_keeps_its_source_in_messages(base):
    with pytest.raises(ModelError, match="^somewhere.toml: rigid 'payload': key 'mass'"):
        changed(dataclasses.replace(base, source="somewhere.toml"), "payload", mass=-1.0)


def test_valid_model_built_in_code_is_accepted(base):
    # lists and numpy scalars stand for numbers, as integers do in a file.
    rebuilt = changed(base, "payload", mass=np.float32(4.0), com=[2.0, 0.0, 0.4])
    assert rebuilt.element("payload").mass == np.float32(4.0)
    assert dataclasses.replace(base, damping=None, boundary={}).boundary == {}


@pytest.mark.parametrize("path", sorted(str(p.relative_to(ROOT)) for p in ROOT.glob("models/**/*.toml")
                                        if p.parent.name != "loads" and p.name != "bundle.toml"))
def test_bundled_models_load(path):
    model = load_model(ROOT / path)
    assert model.elements and model.source == str(ROOT / path)


def test_cli_reports_too_deep_nesting_in_one_line(tmp_path):
    path = write(tmp_path, f"name = {'[' * 5000}{']' * 5000}\n")
    done = subprocess.run([sys.executable, "-m", "linmstmm", "freqs", str(path)],
                          cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and done.stdout == "", done.stderr
    assert done.stderr.splitlines() == [f"linmstmm: error: {path}: invalid TOML: arrays or tables "
                                        f"nested too deeply for the TOML reader"]


def test_released_directions_of_a_spring():
    """The released directions as indices: those of the release, ascending; none for a
    spring with no release, as for one whose release is all False (the same empty,
    read-only indices, so that a spring's kind of joint reads alike either way)."""
    pin = np.array([False, False, False, False, False, True])
    springs = [Spring("s", ("a", "a"), np.ones(6), np.eye(3), release=release)
               for release in (None, np.zeros(6, bool), pin, ~pin)]
    none, unreleased, pinned, all_but = (spring.released for spring in springs)
    assert none.size == 0 and none.dtype == unreleased.dtype and none.tobytes() == unreleased.tobytes()
    assert pinned.tolist() == [5] and all_but.tolist() == [0, 1, 2, 3, 4]
    for indices in (none, pinned):
        with pytest.raises(ValueError):
            indices[...] = 0
    assert springs[2].released is pinned  # found once per spring
