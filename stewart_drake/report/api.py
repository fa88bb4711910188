"""``sd.report``: run the analyses (each section of the report) and write the HTML report with its checks."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from stewart_drake.api.result import Result
from stewart_drake.core.geometry import PRESETS, Platform
from stewart_drake.errors import REPORT_ONE_SUBJECT, UsageError
from stewart_drake.report import command_line, discover_analyses, render, run_analyses, write_report
from stewart_drake.report.subject import from_machine_file, from_platform
from stewart_drake.system.output_folder import OutputFolder
from stewart_drake.system.processes import check_workers


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
    platform: str | Path | Platform | Sequence[str | Path | Platform] | None = None,
    machine: str | Path | None = None,
) -> ReportResult:
    """Run the analyses on the built-in presets, or on a user's machine, and write the HTML report (``index.html``,
    ``checks.json``).

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
        platform: report on these platforms (a preset name, a platform file or a ``Platform``; several: each
            section once per platform) instead of the presets: every section that applies to a user's platform
            runs on it, the others say why they do not apply.
        machine: report on the machine file at this path (its platform with its payload, the loop's fixed-point
            format, its motions and requirements: ``report.subject``).

    Returns:
        The report's index and its checks.

    Raises:
        StewartError: a refused output folder, an unknown analysis, ``jobs`` out of range, both ``platform`` and
            ``machine``, an unreadable platform or machine file.
    """
    if platform is not None and machine is not None:
        raise UsageError(REPORT_ONE_SUBJECT)
    if machine is not None:
        studied = [from_machine_file(machine)]
    elif platform is not None:
        many = isinstance(platform, (list, tuple))
        studied = [from_platform(p) for p in (platform if many else [platform])]
    else:
        studied = [None]
    folder = (
        out
        if isinstance(out, OutputFolder)
        else OutputFolder(str(out), force=force, option="--out", force_option="force=True")
    )
    jobs = jobs if jobs is not None else min(4, os.cpu_count() or 1)
    check_workers("--jobs", jobs)  # the one rule for worker counts (system.processes)
    t0 = time.perf_counter()
    analyses = discover_analyses(only=only)
    sections = []
    for subject in studied:
        done = run_analyses(analyses, quick=quick, jobs=jobs, cache=cache, on_start=on_start, subject=subject)
        for s in done if len(studied) > 1 else ():  # several platforms: each section names its own
            s.title = f"{s.title} — {subject.name}"
            for c in s.checks:
                c.section = s.title
        sections += done
    elapsed = time.perf_counter() - t0
    if studied == [None]:
        meta, title = render.default_meta(sections, command_line(), elapsed, PRESETS), "stewart-drake report"
    else:
        names = ", ".join(s.name for s in studied)
        meta = render.default_meta(sections, command_line(), elapsed)
        del meta["presets"]
        meta["machine" if machine is not None else "platforms"] = ", ".join(f"{s.name} ({s.source})" for s in studied)
        title = f"stewart-drake report: {names}"
    index = write_report(sections, folder, title=title, meta=meta)
    return ReportResult(Path(index), [c for s in sections for c in s.checks], elapsed)
