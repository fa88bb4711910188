"""The design search: pymoo's NSGA-II over the family's variables, evaluations in batches on Dask.

Why NSGA-II (pymoo) and not CMA-ES (``cma``): the requirements name several objectives (peak force, stroke,
base size, frequency, condition) and the answer a designer wants is the trade-off between them, a Pareto
front; NSGA-II returns one in a single run and handles the requirements as constraints (constraint
domination), where CMA-ES is single-objective (a front would need many weighted runs) with constraints
only through penalties. pymoo is maintained and its ask/tell interface lets this module evaluate each
generation where it likes: on Dask.

Determinism: the algorithm draws from ``numpy.random.default_rng(seed)`` (pymoo's ``random_state``) and
nothing else; a design's evaluation depends only on the design and the requirements; the batches are
gathered in order. So the same seed gives the same generations and the same front with any number of
workers (a test runs 1 and 2).

Resume: every evaluated design is appended (flushed) to ``evaluations.jsonl`` in the output folder, under a
header with the search's key (a hash of the requirements, the seed and the population size). A search
started again with the same key replays the algorithm from the seed and takes each design it asks for
from that file when present (JSON keeps every float bit for bit), evaluating only the rest: an
interrupted search picks up where it stopped, and a larger ``--budget`` continues a finished one.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.evaluator import Evaluator
from pymoo.core.problem import Problem
from pymoo.problems.static import StaticProblem
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from stewart_drake.core.output_folder import claim_in_manifest
from stewart_drake.errors import InfeasibleRequirementsError, SynthesisError
from stewart_drake.synthesis.batch import evaluate_designs
from stewart_drake.synthesis.evaluate import CONSTRAINTS
from stewart_drake.synthesis.requirements import OBJECTIVES, Requirements

CACHE = "evaluations.jsonl"
DEFAULT_POP = 24
MIN_BUDGET, MAX_BUDGET = 2, 200_000


@dataclass
class SearchResult:
    """All evaluated designs (``rows``, in evaluation order, each with x, metrics, f, g), the Pareto front
    (``front``: indices into rows of the feasible non-dominated designs, by the first objective), the seed,
    generations run, designs evaluated now and taken from the cache."""

    requirements: Requirements
    rows: list
    front: list
    seed: int
    pop_size: int
    generations: int
    evaluated: int
    cached: int
    key: str

    def front_rows(self) -> list[dict]:
        return [self.rows[i] for i in self.front]

    def to_dict(self) -> dict:
        return {
            "key": self.key,
            "seed": self.seed,
            "pop_size": self.pop_size,
            "generations": self.generations,
            "designs": len(self.rows),
            "evaluated_now": self.evaluated,
            "from_cache": self.cached,
            "front": [{k: r[k] for k in r if k not in ("g",)} for r in self.front_rows()],
        }


def search_key(req: Requirements, seed: int, pop_size: int) -> str:
    """The key of a search: same key, same sequence of designs."""
    text = json.dumps({"req": req.key(), "seed": seed, "pop": pop_size, "algorithm": "pymoo NSGA2 0.6"})
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_cache(out: Path | None, key: str) -> dict:
    """``{tuple(x): row}`` of the designs already evaluated in ``out`` for ``key``; ``SynthesisError`` when the
    folder holds another search."""
    if out is None or not (out / CACHE).exists():
        return {}
    lines = (out / CACHE).read_text(encoding="utf-8").splitlines()
    head = json.loads(lines[0]) if lines else {}
    if head.get("key") != key:
        raise SynthesisError(SynthesisError.OUT_OTHER.format(out=str(out), old=head.get("key"), new=key))
    rows = {}
    for line in lines[1:]:
        try:
            r = json.loads(line)
        except json.JSONDecodeError:  # a line cut short by an interruption: evaluated again
            continue
        rows[tuple(r["x"])] = r
    return rows


class CacheWriter:
    """Appends evaluated designs to ``out/evaluations.jsonl`` (header first), one flushed line each."""

    def __init__(self, out: Path, key: str):
        out.mkdir(parents=True, exist_ok=True)
        path = out / CACHE
        new = not path.exists() or path.stat().st_size == 0
        cut = not new and path.read_bytes()[-1:] != b"\n"  # a line cut short by an interruption: end it
        self.fh = path.open("a", encoding="utf-8")
        if cut:
            self.fh.write("\n")
        if new:
            self.write({"key": key})
            claim_in_manifest(out, [CACHE], prefix=True)  # append-only: verified by its first bytes

    def write(self, obj: dict) -> None:
        self.fh.write(json.dumps(obj) + "\n")
        self.fh.flush()

    def close(self) -> None:
        self.fh.close()


CHUNK_DESIGNS = 12  # designs per evaluation call, whatever the worker count (see Evaluations)


def evaluate_chunks(req: Requirements, chunks: list[np.ndarray]) -> list[list[dict]]:
    """``evaluate_designs`` of each chunk ``(n_i, n_vars)`` in turn: one task's share of a generation."""
    return [evaluate_designs(req, c) for c in chunks]


class Evaluations:
    """Where batches of designs are evaluated: in this process (``workers`` 0), on a LocalCluster of
    ``workers`` single-threaded processes, or on the Dask cluster at ``scheduler``. Results in order.

    A batch is cut into chunks of ``CHUNK_DESIGNS`` designs whatever the number of workers, and this process
    evaluates the same pieces: each design is computed in the same vectorised batch shapes with 0, 1 or K
    workers, so the results are bitwise the same (not only up to rounding) and the search deterministic. 12 is
    where ``evaluate_designs``' fixed cost per call (~3 ms, the pose terms cached per process) is a tenth of
    the call. Chunk i goes to worker slot i mod n, and a slot's chunks of a generation travel as one task: one
    scheduler round trip per slot and generation, whatever the population (per chunk, the scheduler's and the
    client's CPU held the 2-worker speed-up of a 96-design generation at 1.37×). The requirements are scattered to every worker once, and
    every worker evaluates one design before the search (imports, the pose terms' cache), so no generation
    pays a worker's warm-up.

    Placement: the tasks go one per slot to the workers' threads (a loose restriction: another worker may take
    one if its worker leaves). Left to the scheduler (its queue of tasks and its work stealing), both tasks of a
    generation sometimes ran one after the other on one worker while the other idled: 3 of 20 generations of a
    search, and in one search 2.15 s against 0.3 s of CPU on the two workers (the loaded 2-core machine);
    placed, 0 of 60 generations.
    """

    def __init__(self, req: Requirements, workers: int = 0, scheduler: str | None = None):
        self.req, self.client, self.cluster = req, None, None
        if scheduler is None and workers == 0:
            return
        # deferred: Dask is imported (and a cluster started) only when the search runs on it
        from distributed import Client

        from stewart_drake.workspace.dask_sweep import local_cluster, worker_threads

        if scheduler is None:
            self.cluster = local_cluster(workers)
            self.client = Client(self.cluster)
        else:
            self.client = Client(scheduler)
        self.threads = worker_threads(self.client)
        self.slots = [w for w, n in sorted(self.client.nthreads().items()) for _ in range(n)]
        self.req_future = self.client.scatter(req, broadcast=True)
        self.client.run(evaluate_designs, req, (req.lower + req.upper)[None] / 2)  # warm-up on every worker

    def __call__(self, X: np.ndarray) -> list[dict]:
        chunks = [X[s : s + CHUNK_DESIGNS] for s in range(0, len(X), CHUNK_DESIGNS)]
        if self.client is None or len(X) == 0:
            return [row for part in evaluate_chunks(self.req, chunks) for row in part]
        # chunk i goes to slot i mod n; each slot's chunks travel as one task (one scheduler round trip per
        # slot and generation, not per chunk) and come back in the original order
        n = len(self.slots)
        futures = [
            self.client.submit(
                evaluate_chunks,
                self.req_future,
                chunks[j::n],
                pure=False,
                workers=[slot],
                allow_other_workers=True,
            )
            for j, slot in enumerate(self.slots[: len(chunks)])
        ]
        parts = self.client.gather(futures)
        rows = [None] * len(X)
        for j, part in enumerate(parts):
            for i, c in enumerate(range(j, len(chunks), n)):
                rows[c * CHUNK_DESIGNS : c * CHUNK_DESIGNS + len(chunks[c])] = part[i]
        return rows

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def pareto_front(rows: list[dict]) -> list[int]:
    """Indices of the feasible, non-dominated rows (first of identical designs), by the first objective."""
    seen, idx = set(), []
    for i, r in enumerate(rows):
        if r["error"] is None and max(r["g"]) <= 0 and tuple(r["x"]) not in seen:
            seen.add(tuple(r["x"]))
            idx.append(i)
    if not idx:
        return []
    F = np.array([rows[i]["f"] for i in idx])
    nd = NonDominatedSorting().do(F, only_non_dominated_front=True)
    front = [idx[k] for k in nd]
    return sorted(front, key=lambda i: (tuple(rows[i]["f"]), i))


def run_search(
    req: Requirements,
    out=None,
    budget: int = 480,
    seed: int = 0,
    workers: int = 0,
    scheduler: str | None = None,
    pop_size: int = DEFAULT_POP,
    progress: bool = False,
    engine: Evaluations | None = None,
) -> SearchResult:
    """NSGA-II over ``req``'s variables for ``budget`` design evaluations (whole generations of ``pop_size``);
    ``out`` (a folder) keeps the evaluations for resume. See the module docstring. ``engine``: an ``Evaluations``
    already started (a benchmark times the search without the cluster's start); left open."""
    if not (isinstance(budget, int) and MIN_BUDGET <= budget <= MAX_BUDGET):
        raise SynthesisError(SynthesisError.BUDGET.format(lo=MIN_BUDGET, hi=MAX_BUDGET, value=budget))
    pop_size = max(2, min(pop_size, budget))
    generations = math.ceil(budget / pop_size)
    key = search_key(req, seed, pop_size)
    out = Path(out) if out is not None else None
    cache = load_cache(out, key)
    problem = Problem(
        n_var=len(req.lower), n_obj=len(req.objectives), n_ieq_constr=len(CONSTRAINTS), xl=req.lower, xu=req.upper
    )
    algorithm = NSGA2(pop_size=pop_size)
    algorithm.setup(problem, seed=seed, verbose=False)
    writer = CacheWriter(out, key) if out is not None else None
    bar = None
    if progress:
        from tqdm import tqdm  # deferred: only with a progress bar

        bar = tqdm(total=generations * pop_size, desc="optimize", unit=" design", leave=False)
    rows, evaluated, cached = [], 0, 0
    owned = engine is None
    engine = Evaluations(req, workers, scheduler) if owned else engine
    try:
        for _ in range(generations):
            pop = algorithm.ask()
            X = pop.get("X")
            keys = [tuple(x.tolist()) for x in X]
            todo = [k for k in dict.fromkeys(keys) if k not in cache]
            for k, r in zip(todo, engine(np.array(todo).reshape(-1, X.shape[1])), strict=True):
                cache[k] = r
                if writer is not None:
                    writer.write(r)
            evaluated += len(todo)
            cached += len(X) - len(todo)
            batch = [cache[k] for k in keys]
            rows.extend(batch)
            F = np.array([r["f"] for r in batch], dtype=float)
            G = np.array([r["g"] for r in batch], dtype=float)
            Evaluator().eval(StaticProblem(problem, F=F, G=G), pop)
            algorithm.tell(infills=pop)
            if bar is not None:
                bar.update(len(X))
    finally:
        if owned:
            engine.close()
        if writer is not None:
            writer.close()
        if bar is not None:
            bar.close()
    return SearchResult(req, rows, pareto_front(rows), seed, pop_size, generations, evaluated, cached, key)


def pick_design(result: SearchResult, pick: str = "knee") -> int:
    """Index into ``result.rows`` of the chosen design: ``knee`` (the front's design nearest the ideal point
    once each objective is scaled to [0, 1] over the front), an objective's best (``peak_force``, ...), or a
    row of the front counted from 1."""
    front = result.front
    if not front:
        raise InfeasibleRequirementsError(
            InfeasibleRequirementsError.NO_FEASIBLE.format(n=len(result.rows), worst=least_violated(result.rows))
        )
    F = np.array([result.rows[i]["f"] for i in front])
    if pick == "knee":
        span = F.max(0) - F.min(0)
        Z = (F - F.min(0)) / np.where(span > 0, span, 1.0)
        return front[int(np.argmin(np.linalg.norm(Z, axis=1)))]
    objectives = list(result.requirements.objectives)
    if pick in OBJECTIVES:
        if pick in objectives:
            return front[int(np.argmin(F[:, objectives.index(pick)]))]
        metric, sense, _ = OBJECTIVES[pick]
        return min(front, key=lambda i: sense * result.rows[i][metric])
    if pick.isdigit() and 1 <= int(pick) <= len(front):
        return front[int(pick) - 1]
    raise SynthesisError(SynthesisError.PICK.format(value=pick, valid=", ".join(OBJECTIVES), n=len(front)))


def least_violated(rows: list[dict]) -> str:
    """The constraint most often violated by the least-violating design, for the 'no feasible design' message."""
    ok = [r for r in rows if r["error"] is None]
    if not ok:
        return rows[0]["error"] if rows else "no design evaluated"
    best = min(ok, key=lambda r: sum(max(0.0, g) for g in r["g"]))
    worst = int(np.argmax(best["g"]))
    return f"{CONSTRAINTS[worst]} by {100 * best['g'][worst]:.1f} %"
