"""``sd.report``: run the analyses (each section of the report) and write the HTML report with its checks."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from stewart_drake.api.result import Result
from stewart_drake.core.geometry import PRESETS
from stewart_drake.core.output_folder import OutputFolder
from stewart_drake.core.processes import check_workers
from stewart_drake.report import command_line, discover_analyses, render, run_analyses, write_report


@dataclass(repr=False)
class ReportResult(Result):
    """A written report (``report``).

    Attributes:
        index: the report's ``index.html``.
        checks: every check of every section (``section``, ``what``, ``worst``, ``tolerance``, ``unit``,
            ``passed``).
        elapsed_s: wall time, s.
    """

    index: Path
    checks: list
    elapsed_s: float

    @property
    def failed(self) -> list:
        """The checks that failed."""
        return [c for c in self.checks if not c.passed]

    @property
    def ok(self) -> bool:
        """Every check passed."""
        return not self.failed

    def _fields(self) -> dict:
        return {
            "index": str(self.index),
            "checks": len(self.checks),
            "failed": [
                {"section": c.section, "what": c.what, "worst": c.worst, "tolerance": c.tolerance, "unit": c.unit}
                for c in self.failed
            ],
            "elapsed_s": self.elapsed_s,
        }


def report(
    out: str | Path = "report",
    *,
    only: Sequence[str] | None = None,
    quick: bool = False,
    jobs: int | None = None,
    force: bool = False,
    on_start: Callable[[str], None] | None = None,
    cache: bool = True,
) -> ReportResult:
    """Run the analyses on the built-in presets and write the HTML report (``index.html``, ``checks.json``).

    Args:
        out: the output folder.
        only: run only these analyses (their module names in ``stewart_drake.analyses``).
        quick: smaller samples (a smoke test).
        jobs: analyses run in this many worker processes (default the CPUs, at most 4; 1: in this process).
        force: write into an existing folder that holds other files (they are never touched).
        on_start: called with a line saying how many analyses run in how many processes, how many come
            from the cache.
        cache: take a section whose inputs and code version are unchanged from the result cache under
            ``$STEWART_DRAKE_CACHE`` (``report.cache``: checks and figures exactly as computed) and store
            each section computed; False: every section computed, the cache neither read nor written.

    Returns:
        The report's index and its checks.

    Raises:
        StewartError: a refused output folder, an unknown analysis, ``jobs`` out of range.
    """
    folder = (
        out
        if isinstance(out, OutputFolder)
        else OutputFolder(str(out), force=force, option="--out", force_option="force=True")
    )
    jobs = jobs if jobs is not None else min(4, os.cpu_count() or 1)
    check_workers("--jobs", jobs)  # the one rule for worker counts (core.processes)
    t0 = time.perf_counter()
    analyses = discover_analyses(only=only)
    sections = run_analyses(analyses, quick=quick, jobs=jobs, cache=cache, on_start=on_start)
    elapsed = time.perf_counter() - t0
    meta = render.default_meta(sections, command_line(), elapsed, PRESETS)
    index = write_report(sections, folder, meta=meta)
    return ReportResult(Path(index), [c for s in sections for c in s.checks], elapsed)
