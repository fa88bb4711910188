"""Report assembly: analyses add sections (text, tables, figures, checks) to a ``Report``; ``write``
renders one self-contained HTML file (figures inlined as PNG data URIs, also saved beside it) plus a
``checks.json``, and replaces the output folder atomically.

An analysis script in ``analyses/`` defines ``TITLE``, ``ORDER`` (position in the report) and
``build(section)``; its ``main()`` calls ``run_standalone`` so it also runs on its own.
"""

from __future__ import annotations

import base64
import html
import importlib.util
import io
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..atomic import OutputFolder, atomic_folder
from ..jsonout import dumps_strict

ANALYSES_DIR = Path(__file__).resolve().parents[2] / "analyses"


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

    def text(self, paragraph: str) -> None:
        """A paragraph of plain text (escaped)."""
        self.blocks.append(f"<p>{html.escape(paragraph)}</p>")

    def html(self, fragment: str) -> None:
        """Raw HTML (the caller escapes)."""
        self.blocks.append(fragment)

    def table(self, header: list[str], rows: list[list], caption: str = "", fmt: str = "{:.6g}") -> None:
        """A table; floats formatted with ``fmt``."""
        def cell(v):
            return html.escape(fmt.format(v) if isinstance(v, float) else str(v))

        head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
        body = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in r) + "</tr>" for r in rows)
        cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
        self.blocks.append(f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def figure(self, fig, name: str, caption: str = "") -> None:
        """A matplotlib figure, inlined and saved as ``name.png``; the figure is closed."""
        import matplotlib.pyplot as plt

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
        plt.close(fig)
        data = buf.getvalue()
        self.files[f"{name}.png"] = data
        b64 = base64.b64encode(data).decode()
        cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
        self.blocks.append(f'<figure><img alt="{html.escape(name)}" src="data:image/png;base64,{b64}">{cap}</figure>')

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


def load_analysis(path: Path) -> Analysis:
    spec = importlib.util.spec_from_file_location(f"analyses_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for attr in ("TITLE", "ORDER", "build"):
        if not hasattr(mod, attr):
            raise ValueError(f"analysis {path} lacks {attr}")
    return Analysis(path.stem, mod.TITLE, float(mod.ORDER), mod.build)


def discover_analyses(directory: Path = ANALYSES_DIR, only: list[str] | None = None) -> list[Analysis]:
    """Every ``analyses/*.py`` with TITLE/ORDER/build, in report order; ``only`` filters by file stem."""
    if not directory.is_dir():
        raise FileNotFoundError(f"analyses folder {str(directory)!r} not found (run from a checkout of stewart-drake)")
    found = [load_analysis(p) for p in sorted(directory.glob("*.py")) if not p.name.startswith("_")]
    if only:
        unknown = sorted(set(only) - {a.name for a in found})
        if unknown:
            raise ValueError(f"unknown analysis {unknown[0]!r}; available: {', '.join(a.name for a in found)}")
        found = [a for a in found if a.name in only]
    return sorted(found, key=lambda a: (a.order, a.name))


def run_analyses(analyses: list[Analysis], quick: bool = False, log=None) -> list[Section]:
    """Build each analysis's section, printing progress to ``log`` (default: the current stderr); an
    analysis that raises becomes a failed check."""
    log = log or sys.stderr
    sections = []
    for k, a in enumerate(analyses, 1):
        print(f"[{k}/{len(analyses)}] {a.title} ...", file=log, flush=True)
        t0 = time.perf_counter()
        s = Section(a.title, quick=quick)
        try:
            a.build(s)
        except Exception as e:  # noqa: BLE001 - the report must say which analysis broke, and go on
            s.html(f'<p class="fail">This analysis failed: {html.escape(type(e).__name__)}: {html.escape(str(e))}</p>')
            s.check(f"{a.name} ran to completion", 1.0, 0.0)
        print(f"      done in {time.perf_counter() - t0:.1f} s", file=log, flush=True)
        sections.append(s)
    return sections


_CSS = """
body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:90%}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}
th{background:#eee;text-align:left}caption{caption-side:top;text-align:left;font-style:italic;padding:4px 0}
img{max-width:100%}figure{margin:1em 0}figcaption{font-style:italic;font-size:90%}
.pass{color:#070;font-weight:bold}.fail{color:#b00;font-weight:bold}
"""


def _versions(sections: list[Section]) -> str:
    from importlib.metadata import PackageNotFoundError, version

    def v(pkg):
        try:
            return version(pkg)
        except PackageNotFoundError:
            return "?"

    mode = "quick mode (small samples)" if any(s.quick for s in sections) else "full mode"
    return f"stewart-drake {v('stewart-drake')}, drake {v('drake')}, numpy {v('numpy')}, scipy {v('scipy')}; {mode}."


def render_html(sections: list[Section], title: str = "stewart-drake report") -> str:
    checks = [c for s in sections for c in s.checks]
    n_fail = sum(not c.passed for c in checks)
    anchor = {s.title: f"s{i}" for i, s in enumerate(sections)}
    rows = "".join(
        f"<tr><td style='text-align:left'><a href='#{anchor.get(c.section, '')}'>{html.escape(c.section)}</a></td>"
        f"<td style='text-align:left'>{html.escape(c.what)}</td>"
        f"<td>{c.worst:.4g} {html.escape(c.unit)}</td><td>{c.tolerance:.4g} {html.escape(c.unit)}</td>"
        f"<td class='{'pass' if c.passed else 'fail'}'>{'pass' if c.passed else 'FAIL'}</td></tr>"
        for c in checks
    )
    toc = "".join(f'<li><a href="#s{i}">{html.escape(s.title)}</a></li>' for i, s in enumerate(sections))
    body = "".join(f'<section id="s{i}"><h2>{html.escape(s.title)}</h2>{"".join(s.blocks)}</section>' for i, s in enumerate(sections))
    return (
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title><style>{_CSS}</style></head><body>"
        f"<h1>{html.escape(title)}</h1><p>{html.escape(_versions(sections))}</p><h2>Summary of checks</h2><p>{len(checks)} checks, {n_fail} failed.</p>"
        f"<table><thead><tr><th>section</th><th>what was compared</th><th>worst error</th><th>tolerance</th><th>result</th></tr></thead>"
        f"<tbody>{rows}</tbody></table><h2>Contents</h2><ol>{toc}</ol>{body}</body></html>"
    )


def write_report(sections: list[Section], out_dir, title: str = "stewart-drake report") -> Path:
    """Write ``index.html``, ``checks.json`` and every section file into ``out_dir``, atomically: the
    report is built in a temporary sibling folder and swapped in only when complete."""
    out = out_dir if isinstance(out_dir, OutputFolder) else OutputFolder(out_dir)
    with atomic_folder(out) as tmp:
        for s in sections:
            for name, data in s.files.items():
                (tmp / name).write_bytes(data)
        (tmp / "index.html").write_text(render_html(sections, title), encoding="utf-8")
        checks = [dict(c.__dict__, passed=c.passed) for s in sections for c in s.checks]
        (tmp / "checks.json").write_text(dumps_strict(checks), encoding="utf-8")
    return out.path / "index.html"


def run_standalone(module_file: str, argv=None) -> int:
    """``main()`` of an analysis script: build just that section into ``--out`` (default report/<name>)."""
    import argparse

    path = Path(module_file).resolve()
    ap = argparse.ArgumentParser(description=f"analysis {path.stem}")
    ap.add_argument("--out", default=f"report/{path.stem}")
    ap.add_argument("--quick", action="store_true", help="smaller samples, for smoke tests")
    args = ap.parse_args(argv)
    out = OutputFolder(args.out)
    a = load_analysis(path)
    sections = run_analyses([a], quick=args.quick)
    index = write_report(sections, out, title=a.title)
    print(index)
    return 0 if all(c.passed for s in sections for c in s.checks) else 1
