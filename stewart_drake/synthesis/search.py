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

Resume: every evaluated design is appended to ``evaluations.jsonl`` in the output folder (a generation's new
designs flushed together, as soon as they are evaluated), a ``system.journal`` under a header with the search's key
(a hash of the requirements, the seed and the population size). A search started again with the same key
verifies every line (an edited or damaged line refuses the resume, naming the file and line), checks each row
(variables within their bounds, objectives and constraints those of its metrics), replays the algorithm from the
seed and takes each design it asks for from that file when present (JSON keeps every float bit for bit),
evaluating only the rest: an interrupted search picks up where it stopped, and a larger ``--budget`` continues a
finished one.
"""

from __future__ import annotations

import asyncio
import hashlib
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.evaluator import Evaluator
from pymoo.core.problem import Problem
from pymoo.core.termination import NoTermination
from pymoo.problems.static import StaticProblem
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

from stewart_drake.errors import InfeasibleRequirementsError, JournalError, SynthesisError
from stewart_drake.synthesis.batch import evaluate_designs
from stewart_drake.synthesis.evaluate import (
    CONSTRAINTS,
    INFEASIBLE_F,
    INFEASIBLE_G,
    constraint_values,
    objective_values,
)
from stewart_drake.synthesis.families import home_height
from stewart_drake.synthesis.requirements import OBJECTIVES, Requirements
from stewart_drake.system.journal import JournalWriter, header_line, read_header, read_rows
from stewart_drake.system.output_folder import claim_in_manifest, write_text_atomic

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


def load_cache(out: Path | None, key: str, req: Requirements | None = None) -> dict:
    """``{tuple(x): row}`` of the designs already evaluated in ``out`` for ``key``, every journal line verified
    (``system.journal``: ``JournalError`` naming the file and line of an edited or damaged one) and, with ``req``,
    every row checked against it (``check_row``); ``SynthesisError`` when the folder holds another search."""
    path = None if out is None else out / CACHE
    if path is None or not path.exists():
        return {}
    head = read_header(path)
    if head.get("key") != key:
        raise SynthesisError(SynthesisError.OUT_OTHER.format(out=str(out), old=head.get("key"), new=key))
    rows = {}
    for line, r in read_rows(path, key):
        problem = check_row(req, r) if req is not None else None
        if problem is not None:
            raise JournalError(JournalError.ROW.format(path=str(path), line=line, problem=problem))
        rows[tuple(r["x"])] = r
    return rows


def check_row(req: Requirements, row) -> str | None:
    """What is wrong with a journal ``row`` for ``req``, None if nothing: its variables inside their bounds, and
    its objectives ``f`` and constraints ``g`` those of its own metrics (recomputed, bit for bit)."""
    if not isinstance(row, dict) or not isinstance(row.get("x"), list) or len(row["x"]) != len(req.lower):
        return JournalError.ROW_SHAPE.format(n=len(req.lower))
    x = row["x"]
    for name, v, lo, hi in zip(req.variables, x, req.lower, req.upper, strict=True):
        if not (isinstance(v, float | int) and lo <= v <= hi):
            return JournalError.ROW_BOUND.format(name=name, value=v, lo=lo, hi=hi)
    try:
        if row.get("error") is None:
            f, g = objective_values(req, row), constraint_values(req, row, home_height(req.family, x))
        else:
            f, g = [INFEASIBLE_F] * len(req.objectives), [INFEASIBLE_G] * len(CONSTRAINTS)
    except (KeyError, TypeError, ZeroDivisionError):
        return JournalError.ROW_NO_METRICS
    if row.get("f") != f or row.get("g") != g:
        return JournalError.ROW_METRICS
    return None


class CacheWriter:
    """Appends evaluated designs to ``out/evaluations.jsonl`` (``system.journal``: a verified chain), the header
    written first as a whole file."""

    def __init__(self, out: Path, key: str):
        out.mkdir(parents=True, exist_ok=True)
        path = out / CACHE
        if not path.exists() or path.stat().st_size == 0:
            write_text_atomic(path, header_line(key) + "\n")
            claim_in_manifest(out, [CACHE], prefix=True)  # append-only: verified by its first bytes
        self.journal = JournalWriter(path, key)

    def write_lines(self, lines: list[str]) -> None:
        """Appends rows already encoded (``journal_lines``), one flush for them all."""
        self.journal.append_texts(lines)

    def close(self) -> None:
        self.journal.close()


CHUNK_DESIGNS = 12  # designs per evaluation call, whatever the worker count (see Evaluations)
# Settings of the search's own LocalCluster: the event loops' health tick (every 20 ms by default) and the system
# and memory monitors (0.5 s, 0.1 s) woke the scheduler, the nannies and the workers ~100 times a second: an idle
# 2-worker cluster took 0.11 CPU second per second of the 2-core machine, 0.02 with these (measured). They watch
# for a blocked event loop and for memory; a search's calls are small and bounded before they run.
CLUSTER_CONFIG = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}
WORKER_LOSSES = 3  # a generation is sent again at most this many times when a worker holding an evaluator is lost


def journal_lines(rows: list[dict]) -> list[str]:
    """The rows as the journal's JSON lines (every float bit for bit)."""
    return [json.dumps(r) for r in rows]


def evaluate_chunks(req: Requirements, chunks: list[np.ndarray]) -> list[tuple[list[dict], list[str]]]:
    """``evaluate_designs`` of each chunk ``(n_i, n_vars)`` in turn, with the rows' journal lines (encoded where
    they are computed: on the workers, in parallel, not in the search's serial loop): one slot's share of a
    generation."""
    out = []
    for c in chunks:
        rows = evaluate_designs(req, c)
        out.append((rows, journal_lines(rows)))
    return out


class SlotEvaluator:
    """The search's evaluator on one worker thread, a Dask actor: it holds the requirements (sent once) and runs
    its share of each generation on its worker's thread pool. A call goes from the client to the worker and back,
    not through the scheduler's task states."""

    cpu_seconds = 0.0  # CPU seconds spent in evaluate_chunks (a benchmark tells them from Dask's share)

    def __init__(self, req: Requirements):
        from distributed import get_worker  # deferred: only on a Dask worker

        self.req = req
        self.pool = get_worker().executors["default"]  # the worker's threads (the actors' own executor has one)
        evaluate_designs(req, (req.lower + req.upper)[None] / 2)  # warm-up: imports, the pose terms' cache

    async def evaluate(self, chunks: list[np.ndarray]) -> list[tuple[list[dict], list[str]]]:
        """``evaluate_chunks`` of ``chunks`` on one of the worker's threads."""
        done, cpu = await asyncio.get_running_loop().run_in_executor(self.pool, _timed_chunks, self.req, chunks)
        self.cpu_seconds += cpu
        return done


def _timed_chunks(req: Requirements, chunks: list[np.ndarray]) -> tuple[list, float]:
    """``evaluate_chunks`` and the CPU seconds of the thread that ran it."""
    t0 = time.thread_time()
    done = evaluate_chunks(req, chunks)
    return done, time.thread_time() - t0


class Evaluations:
    """Where batches of designs are evaluated: in this process (``workers`` 0), on a LocalCluster of
    ``workers`` single-threaded processes, or on the Dask cluster at ``scheduler``. Results in order.

    A batch is cut into chunks of ``CHUNK_DESIGNS`` designs whatever the number of workers, and this process
    evaluates the same pieces: each design is computed in the same vectorised batch shapes with 0, 1 or K
    workers, so the results are bitwise the same (not only up to rounding) and the search deterministic. 12 is
    where ``evaluate_designs``' fixed cost per call (~3 ms, the pose terms cached per process) is a tenth of
    the call.

    On Dask, each worker thread holds a ``SlotEvaluator`` actor (the requirements sent once, one design evaluated
    at its start: imports, caches); chunk i goes to slot i mod n, and a slot's chunks of a generation travel as
    one actor call, client to worker and back. Measured on 2 workers (2-core machine, loaded): a generation's round
    trip of two trivial calls took 2.0 ms of this process's CPU and 1.1 ms of each worker's as actor calls, 12.9
    ms and 5.0 ms as tasks (the scheduler's and the workers' task states, ~12 messages per task): the tasks' round
    trip was most of what held the 2-worker speed-up of the default 24-design generation at 1.17x. On a LocalCluster the calls go straight to
    the workers; through ``scheduler`` Dask's default applies (the scheduler relays them). A lost worker (its
    actor with it) gets the generation sent again to new actors on the workers left, up to ``WORKER_LOSSES`` times.
    """

    def __init__(self, req: Requirements, workers: int = 0, scheduler: str | None = None):
        self.req, self.client, self.cluster, self.actors = req, None, None, []
        if scheduler is None and workers == 0:
            return
        # deferred: Dask is imported (and a cluster started) only when the search runs on it
        import dask
        from distributed import Client

        from stewart_drake.workspace.dask_sweep import local_cluster

        if scheduler is None:
            with dask.config.set(CLUSTER_CONFIG):
                self.cluster = local_cluster(workers)
            self.client = Client(self.cluster, direct_to_workers=True)
        else:
            self.client = Client(scheduler)
        self._start_actors()

    def _start_actors(self) -> None:
        """One ``SlotEvaluator`` per worker thread of the cluster now (round robin over the workers)."""
        self.client.wait_for_workers(1)
        slots = [w for w, n in sorted(self.client.nthreads().items()) for _ in range(n)]
        self.futures = [
            self.client.submit(SlotEvaluator, self.req, actor=True, pure=False, workers=[w], allow_other_workers=True)
            for w in slots
        ]
        self.actors = [f.result() for f in self.futures]

    def _lost(self, wait: float = 10.0) -> bool:
        """Whether a worker holding an actor has left (the scheduler's view; a call can fail before the scheduler
        knows, so it is asked again for up to ``wait`` seconds)."""
        end = time.monotonic() + wait
        while True:
            workers, held = self.client.nthreads(), self.client.who_has(self.futures)
            if any(f.status != "finished" or not set(held.get(f.key, ())) & set(workers) for f in self.futures):
                return True
            if time.monotonic() > end:
                return False
            time.sleep(0.1)

    async def _round(self, chunks: list[np.ndarray]) -> list[list[tuple[list[dict], list[str]]]]:
        n = len(self.actors)
        calls = [a.evaluate(chunks[j::n]) for j, a in enumerate(self.actors[: len(chunks)])]
        return [await c for c in calls]

    def __call__(self, X: np.ndarray) -> tuple[list[dict], list[str]]:
        """The rows of designs ``X`` (n, n_vars), in order, and their journal lines."""
        chunks = [X[s : s + CHUNK_DESIGNS] for s in range(0, len(X), CHUNK_DESIGNS)]
        if self.client is None or len(X) == 0:
            done = evaluate_chunks(self.req, chunks)
            return [r for rows, _ in done for r in rows], [t for _, lines in done for t in lines]
        for attempt in range(WORKER_LOSSES + 1):
            try:
                parts = self.client.sync(self._round, chunks)
                break
            except (OSError, RuntimeError):  # a worker lost with its actor (else: raised again)
                if attempt == WORKER_LOSSES or not self._lost():
                    raise
                self._start_actors()
        n = len(self.actors)  # those of the round that answered
        done = [None] * len(chunks)
        for j, part in enumerate(parts):
            done[j::n] = part
        return [r for rows, _ in done for r in rows], [t for _, lines in done for t in lines]

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
    cache = load_cache(out, key, req)
    problem = Problem(
        n_var=len(req.lower), n_obj=len(req.objectives), n_ieq_constr=len(CONSTRAINTS), xl=req.lower, xu=req.upper
    )
    algorithm = NSGA2(pop_size=pop_size)
    # the loop below runs the generations; pymoo's default termination (tolerances on the front, updated every
    # generation: a quarter of tell's CPU) would only be computed and ignored
    algorithm.setup(problem, seed=seed, verbose=False, termination=NoTermination())
    writer = CacheWriter(out, key) if out is not None else None
    bar = None
    if progress:
        from tqdm import tqdm  # deferred: only with a progress bar

        bar = tqdm(total=generations * pop_size, desc="optimize", unit=" design", leave=False)
    rows, evaluated, cached = [], 0, 0
    owned = engine is None
    engine = Evaluations(req, workers, scheduler) if owned else engine
    try:
        for generation in range(generations):
            pop = algorithm.ask()
            if pop is None:  # pymoo has no new design to offer: every variable is fixed (low == high)
                generations = generation
                break
            X = pop.get("X")
            keys = [tuple(x.tolist()) for x in X]
            todo = [k for k in dict.fromkeys(keys) if k not in cache]
            new, lines = engine(np.array(todo).reshape(-1, X.shape[1]))
            cache.update(zip(todo, new, strict=True))
            if writer is not None and lines:
                writer.write_lines(lines)
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
