"""One pool for the whole report: the sections and the heavy parts they declare share the same workers.

An analysis with independent heavy cases declares them with ``parts(quick) -> [(function_name, item), ...]``
(the same calls its ``build`` makes through ``parallel_map(__file__, function_name, items)``). The report
runs those parts as tasks of its own worker pool, beside the other sections, instead of the section
starting a pool of its own inside a worker (nested pools on a 2-core machine: more processes than cores,
each importing Drake again). When all of a section's parts are done the section itself is built, with the
parts' results handed to its worker: ``parallel_map`` there returns them instead of computing them again.
A part that raised is simply not handed over (the section computes it again and reports the error).

``schedule`` keeps at most ``jobs`` tasks in flight and always starts the most expensive ready one (the
analyses' ``COST``; a section whose parts are done goes first), so that the workers finish together. The
parts are declared in the workers (the parent reads the scripts' constants without importing them).
"""

from __future__ import annotations

import heapq
import itertools
import time
from concurrent.futures import FIRST_COMPLETED, wait
from pathlib import Path

# In a report worker: the results of the parts of the section being built, (path, name, repr(item)) -> result.
_DONE: dict = {}
# True in a worker process of the report (or of ``parallel_map``): a ``parallel_map`` there runs in-process.
IN_WORKER = False


def part_key(module_file, name: str, item) -> tuple[str, str, str]:
    """The key of one part: the analysis script, the function, the item (its ``repr``: items are plain
    tuples of numbers and strings, whose ``repr`` is exact)."""
    return (str(Path(module_file).resolve()), name, repr(item))


def precomputed(module_file, name: str, items: list) -> list | None:
    """The results of ``[name(item) for item in items]`` if the report computed them all already, else None."""
    keys = [part_key(module_file, name, it) for it in items]
    if not keys or not all(k in _DONE for k in keys):
        return None
    return [_DONE[k] for k in keys]


def run_part(path: str, name: str, item):
    """A part in a worker: ``(result, wall s, CPU s)``."""
    from stewart_drake.report import call_in_analysis

    global IN_WORKER
    IN_WORKER = True  # a worker of the report's pool: no pool of its own
    t0, c0 = time.perf_counter(), time.process_time()
    result = call_in_analysis(path, name, item)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return result, wall, cpu


def schedule(pool, analyses: list, quick: bool, jobs: int, build_in_worker, on_section, subject=None) -> None:
    """Run every analysis (and its declared parts) on ``pool``, at most ``jobs`` tasks at a time, the
    costliest ready task first. ``build_in_worker(path, quick, done, subject)`` builds a section in a worker
    (``subject``: a user's machine, ``report.subject``, whose sections run their cases themselves: the parts
    are the presets' cases);
    ``on_section(i, future, parts_wall, parts_cpu, n_parts)`` is called as each section's future completes.

    An analysis whose ``parts`` is still in its unimported script (``report.FromScript``) declares them in a
    worker, first of all tasks (the costliest first): that worker imports the script, which it needs anyway
    to run the parts, and the parent imports nothing."""
    from stewart_drake.report import FromScript

    order = itertools.count()
    ready: list = []  # heap of (-priority, order, kind, analysis index, payload)
    waiting, done, declared = {}, {}, {}
    spent = {i: [0.0, 0.0] for i in range(len(analyses))}  # parts' wall and CPU seconds

    def add_parts(i, items):
        declared[i], waiting[i], done[i] = len(items), len(items), {}
        for name, item in items:
            heapq.heappush(ready, (-analyses[i].cost, next(order), "part", i, (name, item)))
        if not items:
            heapq.heappush(ready, (-analyses[i].cost, next(order), "section", i, None))

    for i, a in sorted(enumerate(analyses), key=lambda ia: -ia[1].cost):
        found = getattr(a, "parts", None) if subject is None else None
        if isinstance(found, FromScript):
            heapq.heappush(ready, (-float("inf"), next(order), "declare", i, ("parts", quick)))
        else:
            add_parts(i, list(found(quick)) if found else [])
    running: dict = {}
    while ready or running:
        while ready and len(running) < jobs:
            _, _, kind, i, payload = heapq.heappop(ready)
            path = str(analyses[i].path)
            if kind in ("part", "declare"):
                running[pool.submit(run_part, path, *payload)] = (kind, i, payload)
            else:
                running[pool.submit(build_in_worker, path, quick, done[i], subject)] = (kind, i, None)
        finished, _ = wait(running, return_when=FIRST_COMPLETED)
        for f in finished:
            kind, i, payload = running.pop(f)
            if kind == "section":
                on_section(i, f, *spent[i], declared[i])
                continue
            if kind == "declare":  # a script that fails to import has no parts: its section says why
                add_parts(i, list(f.result()[0]) if f.exception() is None else [])
                continue
            if f.exception() is None:  # a part that raised is recomputed by its section, which reports it
                result, wall, cpu = f.result()
                done[i][part_key(analyses[i].path, *payload)] = result
                spent[i][0] += wall
                spent[i][1] += cpu
            waiting[i] -= 1
            if waiting[i] == 0:  # its parts are done: the section next, before anything else
                heapq.heappush(ready, (-float("inf"), next(order), "section", i, None))
