"""The frozen result of a root search (:class:`linmstmm.roots.RootSearchResult`).

* it cannot be changed: not its attributes, nor its array, nor its mappings, nor
  through what it was built from;
* on the tip-mass cantilever (Iy = Iz: every bending root is double) its roots are
  those ``natural_frequencies`` reports, bit for bit (on one BLAS thread, as there), and agree with the FE route,
  whose frequencies grouped by closeness give the same multiplicities; its
  evaluations are the determinant's count;
* a second search on the same finder leaves the first result as it was, and starts
  its own note and its own count of evaluations;
* ``find_near`` returns the same diagnostics as ``find``; a free beam's result
  counts the FE route's six rigid-body modes and the evaluations of the finder's
  rigid-body check with its first search.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from varied_models import varied_model

from linmstmm.builders import single_beam_model
from linmstmm.fe import fe_frequencies
from linmstmm.model import load_model
from linmstmm.roots import CERTIFIED_STEP, RootSearchResult
from linmstmm.solve import frequency_finder, natural_frequencies
from linmstmm.threads import one_blas_thread

CANTILEVER = Path(__file__).resolve().parents[1] / "models" / "cantilever_tip_mass.toml"
#: The lowest ten of the cantilever end on a simple root (495.8 Hz): no multiple root is cut by the count.
COUNT = 10
#: Frequencies closer than this (relative) are one multiple frequency.
SAME = 1e-9


def grouped(values) -> list[int]:
    """Multiplicities of the ascending ``values``: each within SAME (relative) of the
    one before it joins that one's group."""
    groups: list[int] = []
    for previous, value in zip([None, *values], values):
        if previous is not None and abs(value - previous) <= SAME * value:
            groups[-1] += 1
        else:
            groups.append(1)
    return groups


def fe_tolerance(fe) -> float:
    """Relative agreement to ask of MSTMM against the FE result ``fe``: its own error estimate."""
    return max(1e-9, 3 * float(np.max(fe.error_estimate)))


@pytest.fixture(scope="module")
def cantilever():
    return load_model(CANTILEVER)


def test_the_result_cannot_be_changed(cantilever):
    search = frequency_finder(cantilever)[1].find(4, None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        search.note = "changed"
    with pytest.raises(dataclasses.FrozenInstanceError):
        search.roots = np.zeros(4)
    assert not search.roots.flags.writeable
    with pytest.raises(ValueError):
        search.roots[0] = 0.0
    for mapping in (search.multiplicities, search.last_steps, search.unseparated):
        with pytest.raises(TypeError):
            mapping[1.0] = 0


def test_it_keeps_copies_of_what_it_was_built_from():
    roots, steps, unseparated = [1.0, 2.0, 2.0], {1.0: 1e-15, 2.0: 1e-14}, {}
    search = RootSearchResult(roots, {1.0: 1, 2.0: 2}, steps, unseparated, "", 0, None, 1e9)
    roots[0], steps[1.0], unseparated[2.0] = 5.0, 1.0, (2, 1e-6)
    assert search.roots.tolist() == [1.0, 2.0, 2.0]
    assert dict(search.last_steps) == {1.0: 1e-15, 2.0: 1e-14} and not search.unseparated


def test_the_cantilever_roots_and_multiplicities_are_those_reported_and_fe_s(cantilever):
    _, finder, _ = frequency_finder(cantilever)
    before = finder.determinant.evaluations  # the compiled model's determinant counts on across solves
    with one_blas_thread():  # as natural_frequencies searches: the same rounding
        search = finder.find(COUNT, None)
    spent = finder.determinant.evaluations - before
    reported = natural_frequencies(cantilever, COUNT)
    fe = fe_frequencies(cantilever, count=COUNT)
    assert reported.precision == "float64"  # nothing refined: the roots are the search's
    np.testing.assert_array_equal(search.roots / (2 * np.pi), reported.frequencies_hz)
    np.testing.assert_allclose(search.roots / (2 * np.pi), fe.frequencies_hz, rtol=fe_tolerance(fe))
    assert list(search.multiplicities) == sorted(set(search.roots.tolist()))
    assert list(search.multiplicities.values()) == grouped(fe.frequencies_hz) == grouped(reported.frequencies_hz)
    assert 2 in search.multiplicities.values()
    assert search.evaluations == spent == reported.evaluations
    assert set(search.last_steps) == set(search.multiplicities)
    assert max(search.last_steps.values()) <= CERTIFIED_STEP
    assert search.rigid_body_modes == fe.rigid_body_modes == 0
    assert search.note == "" and not search.unseparated and search.ceiling > search.roots[-1]


def test_a_second_search_leaves_the_first_result_as_it_was(cantilever):
    _, finder, _ = frequency_finder(cantilever)
    first = finder.find(3, None)
    kept = first.roots.copy(), dict(first.multiplicities), dict(first.last_steps), first.evaluations
    second = finder.find(COUNT, None)
    assert len(finder.last_step) > len(kept[2])  # the finder's own record grew
    np.testing.assert_array_equal(first.roots, kept[0])
    assert (dict(first.multiplicities), dict(first.last_steps), first.evaluations) == kept[1:]
    assert first.evaluations + second.evaluations == finder.determinant.evaluations
    assert second.evaluations > 0


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_a_note_belongs_to_the_search_that_stopped_short(engine):
    """Two bodies on springs (tests/varied_models.py, seed 341) have 10 elastic modes (the
    FE route is exact for bodies and springs): counted by the argument principle alone (as
    where the stiffness count cannot decide), a search for 80 stops above them and says
    why, by either engine; a search for 5 on the same finder has nothing to say. (The
    engine is named: "auto" is the compiled one once anything earlier in the process loaded
    the kernels, and where rounding noise stops a search is the engine's own.)"""
    bodies = varied_model(341)[0]
    _, finder, _ = frequency_finder(bodies, engine=engine)
    finder.counter = None
    short = finder.find(80, None)
    fe = fe_frequencies(bodies, count=80)
    np.testing.assert_allclose(short.roots / (2 * np.pi), fe.frequencies_hz, rtol=1e-9)
    assert list(short.multiplicities.values()) == grouped(fe.frequencies_hz)
    assert short.note.startswith("the search stopped at")
    five = finder.find(5, None)
    np.testing.assert_allclose(five.roots, short.roots[:5], rtol=1e-12)
    assert five.note == "" and short.note.startswith("the search stopped at")


def test_find_near_carries_the_diagnostics(cantilever):
    cold = frequency_finder(cantilever)[1].find(COUNT, None)
    _, finder, _ = frequency_finder(cantilever)
    before = finder.determinant.evaluations  # the compiled model's, counting on from the cold search
    near = finder.find_near(cold.roots * (1 + 1e-3), COUNT)
    assert isinstance(near, RootSearchResult)
    np.testing.assert_allclose(near.roots, cold.roots, rtol=1e-12)
    assert list(near.multiplicities.values()) == list(cold.multiplicities.values())
    assert near.evaluations == finder.determinant.evaluations - before > 0
    assert set(near.last_steps) == set(near.multiplicities)
    assert max(near.last_steps.values()) <= CERTIFIED_STEP
    assert near.note == "" and not near.unseparated
    assert near.rigid_body_modes == 0 and near.ceiling == cold.ceiling


def test_a_free_beam_counts_its_rigid_body_modes_and_its_rigid_body_check():
    beam = single_beam_model(None, None, length=2.0, A=1e-3, Iy=2e-7, Iz=3e-7, J=4e-7)
    _, finder, _ = frequency_finder(beam)
    checked = finder.determinant.evaluations  # compiling the model counted its rigid-body zeros
    search = finder.find(4, None)
    fe = fe_frequencies(beam, count=4)
    assert checked > 0 and search.evaluations == finder.determinant.evaluations - checked
    assert search.rigid_body_modes == fe.rigid_body_modes == 6
    np.testing.assert_allclose(search.roots / (2 * np.pi), fe.frequencies_hz, rtol=fe_tolerance(fe))
