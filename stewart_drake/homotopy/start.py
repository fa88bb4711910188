"""Start systems of the parameter homotopy: one generic complex parameter point per architecture
class with all of its isolated solutions, computed once by monodromy and shipped as data.

Monodromy solve (``monodromy_solve``): pick random complex anchors a, b ``(6, 3)`` (with the class's
coincidences) and a random Study point x₀ with g·e = 0 on the chart v·x = 1; choosing s_i = u_i·u_i /
e·e makes x₀ a solution of that parameter point P₀. Then repeatedly track every known solution
around a random triangle P₀ → P₁ → P₂ → P₀ in the complex parameter space (``track`` with γ = 1: the
random complex vertices already avoid the discriminant with probability one); the loop permutes the
solutions, so end points not yet known are new solutions of P₀. Stop when the number of solutions
reaches the class's root count (40 for 6-6, 16 for 3-6; ``study.ROOT_COUNT``), or after
``max_loops``. The count is the literature's; monodromy alone cannot prove it, but it cannot produce
a spurious solution either (each is Newton-refined to a residual at rounding level and checked
distinct).

Files: ``data/start_<kind>.npz`` with a, b (complex (6, 3)), s (complex (6,)), v (complex (8,)),
x (complex (n, 8)), kind, seed. Regenerate with ``scripts/make_fk_start_systems.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from stewart_drake.homotopy.study import GENERAL, ROOT_COUNT, SIX_THREE, THREE_SIX, evaluate, leg_matrices
from stewart_drake.homotopy.track import DONE, TrackOptions, track

DATA = Path(__file__).parent / "data"
DISTINCT_TOL = 1e-6  # relative distance below which two solutions are one


@dataclass(frozen=True)
class StartSystem:
    """A generic complex parameter point of class ``kind`` and its solutions x ``(n, 8)``."""

    kind: str
    a: np.ndarray
    b: np.ndarray
    s: np.ndarray
    v: np.ndarray
    x: np.ndarray
    seed: int

    @property
    def B(self) -> np.ndarray:
        return leg_matrices(self.a, self.b)

    def residual(self) -> float:
        """Max |F| over the stored solutions (should be at rounding level)."""
        n = len(self.x)
        F, _ = evaluate(self.x, np.broadcast_to(self.B, (n, 6, 4, 4)), np.broadcast_to(self.s, (n, 6)), self.v)
        return float(np.abs(F).max())

    def save(self, path) -> None:
        np.savez(path, kind=self.kind, a=self.a, b=self.b, s=self.s, v=self.v, x=self.x, seed=self.seed)


def _cn(rng, *shape):
    return (rng.normal(size=shape) + 1j * rng.normal(size=shape)) / np.sqrt(2)


def random_anchors(kind: str, rng) -> tuple[np.ndarray, np.ndarray]:
    """Random complex anchors a, b ``(6, 3)`` of class ``kind`` (3-6: a coincident in pairs (0,1),
    (2,3), (4,5))."""
    a, b = _cn(rng, 6, 3), _cn(rng, 6, 3)
    if kind in (THREE_SIX, SIX_THREE):
        a[1::2] = a[0::2]
    return a, b


def _distinct(x: np.ndarray, known: np.ndarray) -> np.ndarray:
    """``(n,)`` True where x_k is farther than DISTINCT_TOL (relative) from every known point and
    every earlier x."""
    keep = np.zeros(len(x), bool)
    pool = list(known)
    for k, xk in enumerate(x):
        if not pool or np.min(np.linalg.norm(np.asarray(pool) - xk, axis=1)) > DISTINCT_TOL * np.linalg.norm(xk):
            keep[k] = True
            pool.append(xk)
    return keep


def monodromy_solve(
    kind: str, seed: int = 0, max_loops: int = 200, options: TrackOptions = TrackOptions(), verbose: bool = False
) -> StartSystem:
    """All ``ROOT_COUNT[kind]`` solutions of a random complex parameter point of class ``kind`` by
    monodromy (see the module docstring). Raises RuntimeError when ``max_loops`` loops do not find
    them all."""
    kind = THREE_SIX if kind == SIX_THREE else kind
    rng = np.random.default_rng(seed)
    a, b = random_anchors(kind, rng)
    v = _cn(rng, 8)
    e, g = _cn(rng, 4), _cn(rng, 4)
    g -= (g @ e) / (e @ e) * e
    x0 = np.concatenate([e, g])
    x0 /= x0 @ v
    B = leg_matrices(a, b)
    u = x0[4:][None] + np.einsum("ijk,k->ij", B, x0[:4])
    s = np.einsum("ij,ij->i", u, u) / (x0[:4] @ x0[:4])
    sols = x0[None]
    target = ROOT_COUNT[kind]
    for loop in range(max_loops):
        if len(sols) >= target:
            break
        a1, b1 = random_anchors(kind, rng)
        a2, b2 = random_anchors(kind, rng)
        s1, s2 = _cn(rng, 6) * 2, _cn(rng, 6) * 2
        vertices = [(B, s), (leg_matrices(a1, b1), s1), (leg_matrices(a2, b2), s2), (B, s)]
        x = sols
        ok = np.ones(len(x), bool)
        for (Bp, sp), (Bq, sq) in zip(vertices[:-1], vertices[1:]):
            n = len(x)
            paths = track(x, Bp, Bq, sp, sq, v, 1.0, options)
            ok &= paths.state == DONE
            x = paths.x
        x = x[ok]
        new = x[_distinct(x, sols)]
        if len(new):
            sols = np.concatenate([sols, new])
        if verbose:
            print(f"loop {loop + 1}: {len(sols)} solutions")
    if len(sols) != target:
        raise RuntimeError(f"monodromy found {len(sols)} of {target} solutions of class {kind} in {max_loops} loops")
    return StartSystem(kind, a, b, s, v, sols, seed)


@cache
def load_start_system(kind: str) -> StartSystem:
    """The shipped start system of class ``kind`` (6-3 uses the 3-6 one)."""
    kind = THREE_SIX if kind == SIX_THREE else kind
    name = {GENERAL: "start_6-6.npz", THREE_SIX: "start_3-6.npz"}[kind]
    with np.load(DATA / name) as z:
        return StartSystem(str(z["kind"]), z["a"], z["b"], z["s"], z["v"], z["x"], int(z["seed"]))
