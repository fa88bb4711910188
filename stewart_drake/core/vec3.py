"""Cross products of ``(..., 3)`` float64 vectors with numpy's numbers and less of its overhead: the inverse
dynamics of a feed-forward table takes some thirty per batch of poses."""

from __future__ import annotations

import numpy as np


def cross(a, b) -> np.ndarray:
    """``(..., 3)`` a × b of broadcast ``(..., 3)`` vectors: ``np.cross``'s very operations (each component
    a product, a second product, one subtraction: c0 = a1·b2 − a2·b1, …), so the same bits, without its copies
    of both operands and its axis moves. Operands that are not float64 arrays go to ``np.cross`` itself."""
    if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.dtype == b.dtype == np.float64):
        return np.cross(a, b)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    c0, c1, c2 = out[..., 0], out[..., 1], out[..., 2]
    np.multiply(a1, b2, out=c0)
    tmp = np.multiply(a2, b1, out=...)  # an array also for one vector (numpy's own spelling)
    c0 -= tmp
    np.multiply(a2, b0, out=c1)
    np.multiply(a0, b2, out=tmp)
    c1 -= tmp
    np.multiply(a0, b1, out=c2)
    np.multiply(a1, b0, out=tmp)
    c2 -= tmp
    return out
