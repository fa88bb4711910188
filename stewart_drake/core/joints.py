"""Which points are one physical joint: anchors closer than a tolerance.

Legs share a joint when their anchors coincide (the three plate joints of a 3-6 platform, the three
base joints of a 6-3 one). "Coincide" has one definition here, used by every check and classifier:
two points closer than ``tol`` (Euclidean distance strictly below it, in the points' unit). Each
caller chooses ``tol``: the platform checks an absolute length (``geometry.MIN_ANCHOR_SEPARATION``),
the homotopy classifier one relative to the platform's size.
"""

import numpy as np


def _close(points: np.ndarray, tol: float) -> np.ndarray:
    """``(n, n)`` True where two of the ``(n, d)`` points are closer than ``tol`` (the diagonal too)."""
    p = np.asarray(points, dtype=float)
    return np.linalg.norm(p[:, None] - p[None], axis=-1) < tol


def coincident_groups(points: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The joints of ``(n, d)`` points: ``(first (m,), index (n,))``, the lowest point index of each
    group in increasing order and each point's group (0..m-1, numbered in that order).

    A group is a connected set under "closer than ``tol``": points linked by a chain of close pairs
    are one group, so the grouping does not depend on the order of the points (only its numbering
    does). m = n when all points are distinct. The ``(n, n)`` distance table bounds n: anchors, n <= 6
    in this package."""
    reach = _close(points, tol)
    while True:  # transitive closure by squaring: at most log2(n) + 1 rounds
        wider = (reach.astype(np.intp) @ reach.astype(np.intp)) > 0
        if np.array_equal(wider, reach):
            break
        reach = wider
    first, index = np.unique(np.argmax(reach, axis=1), return_inverse=True)  # lowest member of each group
    return first, index


def first_close_pair(points: np.ndarray, tol: float) -> tuple[int, int] | None:
    """The first pair ``(i, j)``, i < j in row order (i, then j, increasing), of ``(n, d)`` points closer
    than ``tol``; None when all are distinct. Errors name this pair."""
    i, j = np.triu_indices(len(points), 1)
    close = _close(points, tol)[i, j]
    if not np.any(close):
        return None
    k = int(np.argmax(close))
    return int(i[k]), int(j[k])
