"""Report assembly: analyses add sections (text, tables, figures, checks) to a ``Report``; ``write``
renders one self-contained HTML file (figures inlined as PNG data URIs, also saved beside it) plus a
``checks.json``, and replaces the output folder atomically. ``render`` does the HTML: a header (date,
versions, commit, command line, presets), a verdict per section, the checks grouped by section,
then the sections; tables format numbers and units alike everywhere.

Analyses run in worker processes (``jobs``), each returning its picklable ``Section``; the report
keeps the analyses' order whatever order they finish in.

An analysis script in ``analyses/`` defines ``TITLE``, ``ORDER`` (position in the report) and
``build(section)``, optionally ``COST`` (its relative run time: the costliest start first), as plain literals at
its top level so that the report's parent reads them without importing the script (``report.metadata``); its ``main()``
calls ``run_standalone`` so it also runs on its own. An analysis with independent heavy cases can fan them
out with ``parallel_map(__file__, "function_name", items)``, and declare them with ``parts(quick)`` so that
the report runs them in its own pool beside the other sections (``report.parts``). ``section.headline(text)``
sets the figure shown beside the section's verdict. ``section.subject`` is the user's machine the report studies
(``report.subject.Subject``; None: the presets); a script declares ``NEEDS`` (what it needs of that machine) or
``PRESET_ONLY`` (why it studies the presets only), and a section that does not apply says why.
"""

from __future__ import annotations

import base64
import html
import importlib.util
import os
import shlex
import sys
import textwrap
import time
from dataclasses import dataclass, field
from pathlib import Path

from stewart_drake.errors import REPORT_UNKNOWN_ANALYSIS, StewartError, UsageError
from stewart_drake.report import cache, figures, metadata, parts, render
from stewart_drake.report import subject as subjects
from stewart_drake.system.jsonout import dumps_strict
from stewart_drake.system.output_folder import OutputFolder, atomic_folder
from stewart_drake.system.processes import worker_pool

ANALYSES_DIR = Path(__file__).resolve().parents[1] / "analyses"


@dataclass
class Check:
    """One verified comparison: what was compared, the worst error, the tolerance and the verdict."""

    what: str
    worst: float
    tolerance: float
    unit: str = ""
    section: str = ""

    @property
    def passed(self) -> bool:
        return bool(self.worst <= self.tolerance)


@dataclass
class Section:
    """One report section. Methods append HTML blocks; ``files`` are extra artefacts (name -> bytes)."""

    title: str
    quick: bool = False
    blocks: list[str] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)
    files: dict[str, bytes] = field(default_factory=dict)
    headline_text: str = ""
    elapsed: float | None = None  # wall seconds to build (and its parts', summed: ``report.parts``)
    cpu: float | None = None  # CPU seconds of the process that built it and of its parts (not of pools it started)
    parts: int = 0  # how many of its heavy parts the report ran in its shared pool (``report.parts``)
    warnings: list[str] = field(default_factory=list)
    crashed: bool = False  # the analysis raised (never cached)
    cached: bool = False  # given back by the result cache (``report.cache``), not computed in this run
    subject: object = None  # the user's machine it studies (``report.subject.Subject``), None: the presets

    def headline(self, text: str) -> None:
        """The one figure that sums the section up, shown in the report's verdict table (default: the
        tightest check)."""
        self.headline_text = text

    def text(self, paragraph: str) -> None:
        """A paragraph of plain text (escaped)."""
        self.blocks.append(f"<p>{html.escape(paragraph)}</p>")

    def html(self, fragment: str) -> None:
        """Raw HTML (the caller escapes)."""
        self.blocks.append(fragment)

    def table(
        self,
        header: list[str],
        rows: list[list],
        caption: str = "",
        fmt: str | None = None,
        nan_reason: str = "not applicable",
    ) -> None:
        """A table in a scrolling box. Numbers get the report's significant digits whatever ``fmt``
        asks (kept for callers; one format for every table), units in headers are written alike, and a
        NaN shows as an em dash with ``nan_reason``."""
        self.blocks.append(render.table_html(header, rows, caption, nan_reason))

    def figure(self, fig, name: str, caption: str = "") -> None:
        """A matplotlib figure, inlined and saved as ``name.png`` (``report.figures``); the figure is closed."""
        import matplotlib.pyplot as plt

        self.warnings += [f"figure {name}: {w}" for w in unlabelled_axes(fig)]
        try:
            data = figures.png_bytes(fig)
        finally:
            plt.close(fig)
        self.files[f"{name}.png"] = data
        b64 = base64.b64encode(data).decode()
        cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
        if not caption:
            self.warnings.append(f"figure {name}: no caption")
        alt = html.escape(caption or name)
        self.blocks.append(f'<figure><img alt="{alt}" src="data:image/png;base64,{b64}">{cap}</figure>')

    def points3d(self, points, name: str, caption: str, labels=("x [m]", "y [m]", "z [m]")) -> None:
        """A rotatable 3-D view of ``(n, 3)`` points in the page (inline script, no file, no library)."""
        self.blocks.append(render.points3d_html(f"p3d-{name}", points, labels, caption + " (drag to rotate)"))

    def attach(self, name: str, data: bytes, text: str) -> None:
        """An extra file in the report folder (e.g. an HTML animation), linked from the section."""
        self.files[name] = data
        self.blocks.append(f'<p><a href="{html.escape(name)}">{html.escape(text)}</a></p>')

    def check(self, what: str, worst: float, tolerance: float, unit: str = "") -> Check:
        """Record a comparison for the summary table (passes when worst <= tolerance)."""
        c = Check(what, float(worst), float(tolerance), unit, self.title)
        self.checks.append(c)
        return c


@dataclass
class Analysis:
    """An analysis script loaded from ``analyses/``."""

    name: str
    title: str
    order: float
    build: object
    path: Path | None = None
    cost: float = 0.0  # the module's optional COST (relative run time): workers take the costliest first
    parts: object = None  # the module's optional parts(quick): its heavy cases, run in the report's pool
    inputs: tuple | None = None  # a script's declared INPUTS, relative to it (``report.cache``); None: undeclared
    needs: tuple | None = None  # NEEDS: what it needs of a user's machine (``report.subject``); None: presets only
    preset_only: str = ""  # PRESET_ONLY: why it studies the presets only


def _module_at(path: Path):
    """The analysis module in file ``path``: imported as ``stewart_drake.analyses.<stem>`` when it is
    one of the package's own (so an installed package is only read), else loaded from the file."""
    path = Path(path).resolve()
    if path.parent == ANALYSES_DIR:
        return importlib.import_module(f"stewart_drake.analyses.{path.stem}")
    spec = importlib.util.spec_from_file_location(f"analyses_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def load_analysis(path: Path) -> Analysis:
    """The analysis script at ``path``: its metadata read from the source (``report.metadata``, no import:
    the report's parent process only schedules), its ``build`` and ``parts`` imported when first called; a
    script whose metadata are not plain literals is imported now."""
    path = Path(path)
    meta = metadata.read(path)
    if meta is not None:
        return Analysis(
            path.stem,
            meta["TITLE"],
            float(meta["ORDER"]),
            FromScript(path, "build"),
            path,
            float(meta["COST"]),
            FromScript(path, "parts") if meta["parts"] else None,
            _tuple(meta["INPUTS"]),
            _tuple(meta["NEEDS"]),
            meta["PRESET_ONLY"] or "",
        )
    mod = loaded(path)
    for attr in ("TITLE", "ORDER", "build"):
        if not hasattr(mod, attr):
            raise ValueError(f"analysis {path} lacks {attr}")  # internal: the analyses are package modules
    return Analysis(
        path.stem,
        mod.TITLE,
        float(mod.ORDER),
        mod.build,
        path,
        float(getattr(mod, "COST", 0.0)),
        getattr(mod, "parts", None),
        _tuple(getattr(mod, "INPUTS", None)),
        _tuple(getattr(mod, "NEEDS", None)),
        getattr(mod, "PRESET_ONLY", "") or "",
    )


def _tuple(value) -> tuple | None:
    """A script's list constant as a tuple of strings (None stays None)."""
    return None if value is None else tuple(str(v) for v in value)


@dataclass(frozen=True)
class FromScript:
    """The function ``name`` of the analysis script at ``path``, imported when first called."""

    path: Path
    name: str

    def __call__(self, *args):
        return getattr(loaded(self.path), self.name)(*args)


def discover_analyses(directory: Path = ANALYSES_DIR, only: list[str] | None = None) -> list[Analysis]:
    """Every ``analyses/*.py`` with TITLE/ORDER/build, in report order; ``only`` filters by file stem."""
    if not directory.is_dir():
        raise FileNotFoundError(f"analyses folder {str(directory)!r} not found")
    found = [load_analysis(p) for p in sorted(directory.glob("*.py")) if not p.name.startswith("_")]
    if only:
        unknown = sorted(set(only) - {a.name for a in found})
        if unknown:
            raise UsageError(
                REPORT_UNKNOWN_ANALYSIS.format(name=unknown[0], available=", ".join(a.name for a in found))
            )
        found = [a for a in found if a.name in only]
    return sorted(found, key=lambda a: (a.order, a.name))


def unlabelled_axes(fig) -> list[str]:
    """Axes of a matplotlib figure that show data but lack an axis label (x, y, and z for 3-D)."""
    out = []
    for k, ax in enumerate(fig.axes):
        if (
            ax.get_label() == "<colorbar>"
            or not ax.get_visible()
            or not ax.axison
            or not (ax.lines or ax.collections or ax.images or ax.patches)
        ):
            continue
        getters = [("x", ax.get_xlabel), ("y", ax.get_ylabel)] + (
            [("z", ax.get_zlabel)] if hasattr(ax, "get_zlabel") else []
        )
        missing = [a for a, get in getters if not get().strip()]
        shared_x = ax.get_shared_x_axes().get_siblings(ax)
        if "x" in missing and any(o is not ax and o.get_xlabel().strip() for o in shared_x):
            missing.remove("x")  # shared x axis labelled on another row
        shared_y = ax.get_shared_y_axes().get_siblings(ax)
        if "y" in missing and any(o is not ax and o.get_ylabel().strip() for o in shared_y):
            missing.remove("y")
        if missing:
            out.append(f"axes {k} ({ax.get_title() or 'untitled'}) has no {'/'.join(missing)} label")
    return out


_MODULES: dict = {}


def loaded(path) -> object:
    """The analysis script at ``path`` as a module, imported once per process (a script outside the package:
    once per content, so an edited script is run as it now reads)."""
    path = Path(path).resolve()
    key = (str(path), None if path.parent == ANALYSES_DIR else path.read_bytes())
    if key not in _MODULES:
        _MODULES[key] = _module_at(path)
    return _MODULES[key]


def call_in_analysis(path: str, name: str, item):
    """``name(item)`` of the analysis script at ``path`` (loaded once per worker process)."""
    import matplotlib

    matplotlib.use("Agg")
    return getattr(loaded(path), name)(item)


def _call_in_pool(path: str, name: str, item):
    """``call_in_analysis`` in a worker of ``parallel_map``'s pool (which starts no pool of its own)."""
    parts.IN_WORKER = True
    return call_in_analysis(path, name, item)


def parallel_map(module_file: str, name: str, items: list, jobs: int | None = None) -> list:
    """``[f(item) for item in items]`` where ``f`` is the function ``name`` of the analysis script
    ``module_file`` (pass ``__file__``), computed in ``jobs`` worker processes (default: the CPUs; in a
    worker of the report: in this process, the report's pool keeping the CPUs busy). For an analysis's
    independent heavy cases; ``item`` and the results must be picklable. In order. Parts the report already
    ran in its shared pool (``report.parts``) are given back, not computed again."""
    done = parts.precomputed(module_file, name, items)
    if done is not None:
        return done
    jobs = 1 if parts.IN_WORKER else min(len(items), jobs or os.cpu_count() or 1)
    if jobs <= 1:
        return [call_in_analysis(str(Path(module_file).resolve()), name, it) for it in items]
    with worker_pool(jobs) as pool:  # spawned, dying with this process, terminated on Ctrl-C/SIGTERM
        return list(
            pool.map(_call_in_pool, [str(Path(module_file).resolve())] * len(items), [name] * len(items), items)
        )


def build_section(analysis: Analysis, quick: bool = False, subject=None) -> Section:
    """Run one analysis into a new ``Section`` (timed) of ``subject`` (``report.subject.Subject``; None: the
    presets); an analysis that raises becomes a failed check."""
    if isinstance(analysis.build, FromScript):  # its import is not the section's time (as when it was discovered)
        try:
            loaded(analysis.build.path)
        except Exception:  # noqa: BLE001, S110 - raised again by the build below, and reported as its failure
            pass
    t0, c0 = time.perf_counter(), time.process_time()
    s = Section(analysis.title, quick=quick, subject=subject)
    try:
        analysis.build(s)
    except Exception as e:  # noqa: BLE001 - the report must say which analysis broke, and go on
        s.html(f'<p class="fail">This analysis failed: {html.escape(type(e).__name__)}: {html.escape(str(e))}</p>')
        s.check(f"{analysis.name} ran to completion", 1.0, 0.0)
        s.crashed = True
    s.elapsed, s.cpu = time.perf_counter() - t0, time.process_time() - c0
    return s


def _build_in_worker(path: str, quick: bool, done: dict | None = None, subject=None) -> Section:
    """A section in a report worker; ``done``: its parts, computed already (``report.parts``)."""
    import matplotlib

    matplotlib.use("Agg")
    parts.IN_WORKER = True
    parts._DONE.clear()
    parts._DONE.update(done or {})
    try:
        return build_section(load_analysis(Path(path)), quick, subject)
    finally:
        parts._DONE.clear()


def _progress(k: int, n: int, s: Section, log, done: int | None = None) -> None:
    """One line per finished section: its number in the report's order ``k`` of ``n`` (and, when sections
    finish out of order, how many are done), its title shortened at a word, its checks and time."""
    ok = sum(c.passed for c in s.checks)
    cpu = "" if s.cpu is None else f" (CPU {s.cpu:.1f} s)"
    cpu += ", from the cache (--no-cache to recompute)" if s.cached else ""
    cpu += f", {s.parts} parts in the shared pool" if s.parts else ""
    count = f"section {k}/{n}" + ("" if done is None else f", {done} done")
    title = textwrap.shorten(s.title, 70, placeholder=" …")
    print(f"[{count}] {title}: {ok}/{len(s.checks)} checks passed, {s.elapsed:.1f} s{cpu}", file=log, flush=True)
    for w in s.warnings:
        print(f"      warning: {w}", file=log, flush=True)


def run_analyses(
    analyses: list[Analysis],
    quick: bool = False,
    log=None,
    jobs: int = 1,
    cache: bool = False,
    on_start=None,
    subject=None,
) -> list[Section]:
    """Build each analysis's section, in ``jobs`` worker processes (1: in this process), printing a
    line per analysis as it finishes to ``log`` (default: the current stderr, not the one at import
    time); the sections come back in the analyses' order. ``cache``: take a section whose inputs and
    code are unchanged from the result cache (``report.cache``) and store each one computed.
    ``on_start``: called with a line saying how many analyses run, and in how many processes. ``subject``: the
    user's machine the sections study (``report.subject.Subject``; None: the presets); an analysis that does not
    apply to it gives a section that says why (``report.subject.not_applicable``)."""
    log = log or sys.stderr
    reasons = [subjects.not_applicable(a, subject) if subject is not None else "" for a in analyses]
    if any(reasons):
        applicable = [a for a, r in zip(analyses, reasons) if not r]
        built = iter(run_analyses(applicable, quick, log, jobs, cache, on_start, subject))
        out = []
        for a, r in zip(analyses, reasons):
            if r:
                out.append(_not_applicable(a, subject, r, quick))
                print(f"[not applicable] {a.title}: {r}", file=log, flush=True)
            else:
                out.append(next(built))
        return out
    if cache:
        return _run_cached(analyses, quick, log, jobs, on_start, subject)
    n = len(analyses)
    if on_start:
        on_start(_start_line(n, jobs))
    if jobs <= 1 or n <= 1:
        sections = []
        for k, a in enumerate(analyses, 1):
            sections.append(build_section(a, quick, subject))
            _progress(k, n, sections[-1], log)
        return sections
    sections: list[Section | None] = [None] * n
    finished = [0]

    def on_section(i, f, parts_wall, parts_cpu, n_parts):
        try:
            s = f.result()
        except Exception as e:  # noqa: BLE001 - a worker that died (not an analysis that raised)
            s = Section(analyses[i].title, quick=quick)
            s.html(
                f'<p class="fail">This analysis failed in its worker: {html.escape(type(e).__name__)}: {html.escape(str(e))}</p>'
            )
            s.check(f"{analyses[i].name} ran to completion", 1.0, 0.0)
            s.elapsed, s.crashed = 0.0, True
        s.parts = n_parts
        s.elapsed = (s.elapsed or 0.0) + parts_wall
        s.cpu = (s.cpu or 0.0) + parts_cpu
        sections[i] = s
        finished[0] += 1
        _progress(i + 1, n, s, log, finished[0])

    # spawned workers (no fork of Drake's threads), dying with this process; one pool for the sections and
    # their parts, the costliest ready task first (ORDER is no guide; COST is), so the workers finish together
    with worker_pool(jobs) as pool:
        parts.schedule(pool, analyses, quick, jobs, _build_in_worker, on_section, subject)
    return sections


def _not_applicable(analysis: Analysis, subject, reason: str, quick: bool) -> Section:
    """The section of an analysis that does not apply to ``subject``: a visible line saying why, no checks."""
    s = Section(analysis.title, quick=quick, subject=subject, elapsed=0.0)
    s.html(subjects.not_applicable_html(subject, reason))
    s.headline(f"not applicable: {reason}")
    return s


def _start_line(n: int, jobs: int, cached: int = 0) -> str:
    """'running N analyses in J processes' (in this process where one runs, or with one job), and how many
    sections come from the cache."""
    where = f"in {jobs} processes" if jobs > 1 and n > 1 else "in this process"
    return f"running {n} analys{'es' if n != 1 else 'is'} {where}" + (f", {cached} from the cache" if cached else "")


def _run_cached(analyses: list[Analysis], quick: bool, log, jobs: int, on_start=None, subject=None) -> list[Section]:
    """``run_analyses`` through the result cache: hits first, then the misses computed and stored (a section
    without a key, ``cache.section_key``, is computed every time)."""
    keys = [cache.section_key(a, quick, subject) for a in analyses]
    sections: list[Section | None] = [cache.load(k) for k in keys]
    for s in sections:
        if s is not None:
            s.cached = True
    hits = [i for i, s in enumerate(sections) if s is not None]
    todo = [i for i, s in enumerate(sections) if s is None]
    if on_start:
        on_start(_start_line(len(todo), jobs, len(hits)))
    for k, i in enumerate(hits, 1):
        _progress(k, len(analyses), sections[i], log)
    for i, s in zip(todo, run_analyses([analyses[i] for i in todo], quick, log, jobs, subject=subject)):
        sections[i] = s
        if not s.crashed:
            cache.store(keys[i], s)
    return sections


def render_html(sections: list[Section], title: str = "stewart-drake report", meta: dict | None = None) -> str:
    """The report page (see ``render``); ``meta``: the header's fields (default: date, versions, commit)."""
    return render.render_html(sections, title, meta if meta is not None else render.default_meta(sections))


def write_report(
    sections: list[Section], out_dir, title: str = "stewart-drake report", meta: dict | None = None
) -> Path:
    """Write ``index.html``, ``checks.json`` and every section file into ``out_dir``, atomically: the
    report is built in a temporary sibling folder and swapped in only when complete."""
    out = out_dir if isinstance(out_dir, OutputFolder) else OutputFolder(out_dir)
    with atomic_folder(out) as tmp:
        for s in sections:
            for name, data in s.files.items():
                (tmp / name).write_bytes(data)
        (tmp / "index.html").write_text(render_html(sections, title, meta), encoding="utf-8")
        checks = [dict(c.__dict__, passed=c.passed) for s in sections for c in s.checks]
        (tmp / "checks.json").write_text(dumps_strict(checks), encoding="utf-8")
    return out.path / "index.html"


def command_line(argv=None) -> str:
    """The command as typed (``stewart-drake`` for the CLI module)."""
    argv = list(sys.argv if argv is None else argv)
    prog = (
        "stewart-drake" if argv and argv[0].endswith(("cli.py", "stewart-drake", "__main__.py")) else Path(argv[0]).name
    )
    return shlex.join([prog, *argv[1:]])


def run_standalone(module_file: str, argv=None) -> int:
    """``main()`` of an analysis script: build just that section into ``--out`` (default report/<name>), on the
    presets or on ``--platform FILE|NAME`` / ``--machine FILE``."""
    import argparse

    path = Path(module_file).resolve()
    ap = argparse.ArgumentParser(description=f"analysis {path.stem}")
    ap.add_argument("--out", default=f"report/{path.stem}")
    ap.add_argument("--quick", action="store_true", help="smaller samples, for smoke tests")
    who = ap.add_mutually_exclusive_group()
    who.add_argument("--platform", metavar="FILE|NAME", help="run on this platform file or preset")
    who.add_argument("--machine", metavar="FILE", help="run on this machine file (see report --machine)")
    args = ap.parse_args(argv)
    out = OutputFolder(args.out)
    subject = None
    try:
        if args.machine is not None:
            subject = subjects.from_machine_file(args.machine)
        elif args.platform is not None:
            subject = subjects.from_platform(args.platform)
    except StewartError as e:
        print(f"{path.stem}: error: {e}", file=sys.stderr)
        return getattr(e, "exit_code", 2)
    a = load_analysis(path)
    t0 = time.perf_counter()
    sections = run_analyses([a], quick=args.quick, subject=subject)
    meta = render.default_meta(
        sections, command_line([str(path), *(sys.argv[1:] if argv is None else argv)]), time.perf_counter() - t0
    )
    index = write_report(sections, out, title=a.title, meta=meta)
    print(index)
    return 0 if all(c.passed for s in sections for c in s.checks) else 1
