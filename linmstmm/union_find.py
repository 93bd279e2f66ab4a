"""Connected components of a small graph by union–find: shared by the kinematic
count of rigid-body modes (:mod:`linmstmm.rigid_motion`) and the FE route's
check that every segment is clamped (:mod:`linmstmm.fe.rigid_motions`), which
must not depend on the transfer-matrix side."""
from __future__ import annotations

import numpy as np


def components(count: int, edges) -> np.ndarray:
    """The connected component of each of ``count`` nodes joined by ``edges``.

    A forest in which every node's parent is a lower node (trees joined under the
    lower root, paths halved on the way up): so each tree's root is its lowest node,
    and numbering the nodes in order gives each the number of its parent, found
    before it, or a new one at a root.

    Parameters
    ----------
    count : int
        Nodes, numbered 0 .. count − 1.
    edges : iterable of (int, int)
        The node pairs joined.

    Returns
    -------
    numpy.ndarray, shape (count,), int
        Each node's component, numbered 0, 1, ... in order of each one's lowest node.
    """
    parent = list(range(count))
    for a, b in edges:
        while parent[a] != a:
            parent[a] = a = parent[parent[a]]
        while parent[b] != b:
            parent[b] = b = parent[parent[b]]
        if a < b:
            parent[b] = a
        elif b < a:
            parent[a] = b
    labels, roots = [0] * count, 0
    for node, up in enumerate(parent):
        if up == node:
            labels[node], roots = roots, roots + 1
        else:
            labels[node] = labels[up]
    return np.array(labels, dtype=int)
