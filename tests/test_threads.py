"""One BLAS thread while solving (linmstmm.threads): every BLAS library at one thread
inside, the thread counts found on entry back on exit, nested uses included."""
from __future__ import annotations

import scipy.linalg  # noqa: F401  (its BLAS loaded before the libraries are looked up)
from threadpoolctl import threadpool_info, threadpool_limits

from linmstmm.threads import one_blas_thread, single_blas_thread


def blas_threads() -> list[int]:
    return [library["num_threads"] for library in threadpool_info() if library["user_api"] == "blas"]


def test_one_thread_inside_and_the_counts_found_restored_after():
    with threadpool_limits(limits=2, user_api="blas"):
        before = blas_threads()
        assert before and all(threads == 2 for threads in before)
        with one_blas_thread():
            assert all(threads == 1 for threads in blas_threads())
            with one_blas_thread():  # nested: left at one, and still one after the inner exit
                assert all(threads == 1 for threads in blas_threads())
            assert all(threads == 1 for threads in blas_threads())
        assert blas_threads() == before


def test_the_decorated_solve_runs_on_one_thread_and_restores_on_error():
    seen = []

    @single_blas_thread
    def failing():
        seen.extend(blas_threads())
        raise ValueError("inside")

    with threadpool_limits(limits=2, user_api="blas"):
        before = blas_threads()
        try:
            failing()
        except ValueError:
            pass
        assert seen and all(threads == 1 for threads in seen)
        assert blas_threads() == before


def fe_route_threads(monkeypatch, threaded_nodes=None) -> list[int]:
    """The BLAS thread counts seen by the FE route's eigensolve of a 4-body chain under a
    two-thread limit (``threaded_nodes``: THREADED_NODES for this call)."""
    import linmstmm.fe.frequencies as frequencies
    from linmstmm.builders import spring_chain

    seen = []
    solve = frequencies.fe_modes

    def watched(*args, **kwargs):
        seen.extend(blas_threads())
        return solve(*args, **kwargs)

    monkeypatch.setattr(frequencies, "fe_modes", watched)
    if threaded_nodes is not None:
        monkeypatch.setattr(frequencies, "THREADED_NODES", threaded_nodes)
    with threadpool_limits(limits=2, user_api="blas"):
        frequencies.fe_frequencies(spring_chain(4), 2)
    assert seen
    return seen


def test_the_fe_route_solves_a_small_model_on_one_thread(monkeypatch):
    """fe_frequencies (the ``fe`` command's route) sets BLAS to one thread for its
    eigensolves as the transfer-matrix solve does: OpenBLAS's second thread made the
    launcher's ten lowest 16 times slower on a busy two-core machine."""
    assert all(threads == 1 for threads in fe_route_threads(monkeypatch))


def test_the_fe_route_keeps_the_threads_for_a_model_of_many_nodes(monkeypatch):
    """Above THREADED_NODES (the 10,000-body chain: 0.80 s on two threads, 1.19 s on one)."""
    assert all(threads == 2 for threads in fe_route_threads(monkeypatch, threaded_nodes=3))
