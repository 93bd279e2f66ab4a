"""The joined arrays a triplet list keeps (:meth:`linmstmm.fe.layout._Triplets.joined`):
made once and shared until entries are added, then made anew, so that they always
hold every entry added (the node constraints' triplets are added to after the
counter has read them); and the compressed rows made of them are scipy's."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from linmstmm.fe.layout import _Triplets


def entries(triplets):
    """(rows, cols, values) of ``triplets`` joined afresh from its lists."""
    return tuple(np.concatenate(part) if part else np.zeros(0) for part in
                 (triplets.rows, triplets.cols, triplets.values))


def same(joined, expected):
    return all(np.array_equal(a, b) for a, b in zip(joined, expected))


def test_joined_arrays_follow_every_addition():
    triplets = _Triplets(repeats=True)
    assert [part.size for part in triplets.joined()] == [0, 0, 0]
    triplets.add(triplets.new_rows(2)[:, None], [[0, 3], [1, 3]], [[1.0, 2.0], [3.0, 4.0]])
    first = triplets.joined()
    assert first is triplets.joined()                          # kept
    assert same(first, entries(triplets))
    assert [part.dtype for part in first] == [np.int64, np.int64, np.float64]
    twin = triplets.copy()
    triplets.add(1, 3, 5.0)                                    # a repeated position
    assert same(triplets.joined(), entries(triplets)) and triplets.joined()[0].size == 5
    assert same(first, entries(twin)) and same(twin.joined(), entries(twin))
    other = _Triplets()
    other.add(other.new_rows(1), [2], [7.0])
    twin.extend(other)
    assert same(twin.joined(), entries(twin)) and twin.joined()[0][-1] == 2
    for made in (triplets, twin):
        rows, cols, values = entries(made)
        reference = sp.coo_matrix((values, (rows, cols)), shape=(made.n_rows, 4)).tocsr()
        reference.eliminate_zeros()
        ours = made.compressed(4)
        assert np.array_equal(ours.indptr, reference.indptr) and np.array_equal(ours.indices, reference.indices)
        assert np.array_equal(ours.data, reference.data)
