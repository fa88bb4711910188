"""HTML rendering of the report: number and unit formatting, tables, the header, the verdicts and the
grouped check table. Pure string work (no Drake, no matplotlib).

Conventions: numbers get ``DIGITS`` significant digits (fixed notation from 1e-3 to 1e5, scientific
outside), right-aligned in tabular figures; text is left-aligned; a unit is written after its quantity
as ``name [unit]`` in headers (``[mm]``, ``(mm)`` and a bare trailing ``mm`` are read alike); a missing
value (NaN) is shown as an em dash whose tooltip says why.
"""

from __future__ import annotations

import html
import math
import re
import subprocess
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

DIGITS = 4
# Units recognised at the end of a header without brackets ("max |leg err| mm").
BARE_UNITS = (
    "mm",
    "m",
    "s",
    "ms",
    "µs",
    "us",
    "N",
    "N/m",
    "N·s/m",
    "N/(m·s)",
    "deg",
    "rad",
    "kg",
    "Hz",
    "%",
    "mm/s",
    "m/s",
    "kg·m²",
    "kN/m",
    "V",
    "A",
    "W",
    "cycles",
    "µm",
    "nm",
)
_BRACKET_UNIT = r"[A-Za-zµ°·/²³%0-9^⁻¹()\-−]{1,12}"
_UNIT_RE = re.compile(
    rf"^(?P<name>.*?)\s*(?:\[(?P<b>{_BRACKET_UNIT})\]|\((?P<p>[A-Za-zµ°·/²³%0-9^⁻¹\-−]{{1,12}})\)|\s(?P<u>"
    + "|".join(re.escape(u) for u in sorted(BARE_UNITS, key=len, reverse=True))
    + r"))$"
)

_NUMERIC_TEXT = re.compile(r"^\s*[-+−]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*$")

CSS = """
body{font-family:system-ui,sans-serif;max-width:1180px;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.45}
h1{margin-bottom:.2em}h2{border-bottom:1px solid #ccc;padding-bottom:.15em;margin-top:1.6em}
.meta{font-size:90%;color:#444}.meta td,.meta th{border:none;padding:1px 10px 1px 0;vertical-align:top}
.scroll{overflow-x:auto;max-width:100%;margin:1em 0}
table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #bbb;padding:3px 8px;text-align:left;vertical-align:top}
th{background:#eee;font-weight:600}td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
th.num{text-align:right}.unit{font-weight:normal;color:#555;white-space:nowrap}
.tcap{font-style:italic;margin:1em 0 -.6em 0}
td.na{color:#888;text-align:center}td.nw{white-space:nowrap}
img{max-width:100%;height:auto}figure{margin:1em 0}figcaption{font-style:italic;font-size:90%;max-width:900px}
.pass{color:#070;font-weight:bold}.fail{color:#b00;font-weight:bold}
details{margin:.3em 0}summary{cursor:pointer}summary .fail,summary .pass{margin-left:.5em}
.verdicts td:first-child{max-width:520px}
nav ol{columns:2;font-size:95%}
"""


def format_number(v, digits: int = DIGITS) -> str:
    """``v`` with ``digits`` significant digits: fixed notation for 1e-3 <= |v| < 1e5 (trailing zeros
    kept: they state the precision), scientific outside; integers (and bools) as they are."""
    if isinstance(v, bool):
        return str(v)
    if isinstance(v, int):
        return str(v)
    v = float(v)
    if math.isnan(v):
        return "—"
    if math.isinf(v):
        return "∞" if v > 0 else "−∞"
    if v == 0:
        return "0"
    a = abs(v)
    if 1e-3 <= a < 1e5:
        decimals = max(0, digits - 1 - math.floor(math.log10(a)))
        s = f"{v:.{decimals}f}"
        # rounding may add a digit (9.9996 -> 10.000): drop one decimal then
        if decimals and len(s.replace("-", "").replace(".", "").lstrip("0")) > digits:
            s = f"{v:.{decimals - 1}f}"
        return s.replace("-", "−")
    return f"{v:.{digits - 1}e}".replace("-", "−")


def is_number(v) -> bool:
    """An int or float (Python or numpy), not a bool."""
    if isinstance(v, (bool, np.bool_)):
        return False
    return isinstance(v, (int, float, np.integer, np.floating))


def split_unit(header: str) -> tuple[str, str]:
    """``("max |leg err|", "mm")`` from ``"max |leg err| mm"``, ``"… [mm]"`` or ``"… (mm)"``; ("x", "") otherwise."""
    m = _UNIT_RE.match(str(header).strip())
    if not m or not m.group("name"):
        return str(header), ""
    return m.group("name"), m.group("b") or m.group("p") or m.group("u")


def header_cell(h: str, numeric: bool) -> str:
    name, unit = split_unit(h)
    u = f' <span class="unit">[{html.escape(unit)}]</span>' if unit else ""
    return f"<th{' class=num' if numeric else ''}>{html.escape(name)}{u}</th>"


def cell(v, nan_reason: str = "not applicable") -> tuple[str, bool]:
    """(the ``<td>``, whether it is a number)."""
    if is_number(v):
        v = v.item() if hasattr(v, "item") else v
        if isinstance(v, float) and math.isnan(v):
            return (
                f'<td class="na" title="{html.escape(nan_reason)}">— <small>({html.escape(nan_reason)})</small></td>',
                True,
            )
        return f'<td class="num">{format_number(v)}</td>', True
    text = str(v)
    if _NUMERIC_TEXT.match(text):  # a number the analysis formatted itself: aligned as a number
        return f'<td class="num">{html.escape(text.replace("-", "−"))}</td>', True
    if text.strip().lower() == "nan":
        return (
            f'<td class="na" title="{html.escape(nan_reason)}">— <small>({html.escape(nan_reason)})</small></td>',
            True,
        )
    short = len(text) <= 24  # a name or a label: kept on one line
    return f"<td{' class=nw' if short else ''}>{html.escape(text)}</td>", False


def table_html(header: list, rows: list[list], caption: str = "", nan_reason: str = "not applicable") -> str:
    """A table in a horizontally scrolling box: text left, numbers right with ``DIGITS`` significant
    digits, units in the header, NaN as an em dash with ``nan_reason``."""
    cells = [[cell(v, nan_reason) for v in r] for r in rows]
    numeric = [bool(cells) and all(c[k][1] for c in cells if k < len(c)) for k in range(len(header))]
    head = "".join(header_cell(h, numeric[k]) for k, h in enumerate(header))
    body = "".join("<tr>" + "".join(c[0] for c in r) + "</tr>" for r in cells)
    # The caption above the box, not a <caption>: a narrow table would squeeze it into a narrow column.
    cap = f'<p class="tcap">{html.escape(caption)}</p>' if caption else ""
    return f'{cap}<div class="scroll"><table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>'


# ----------------------------------------------------------------------------------------------
# Header, verdicts, grouped checks


def versions() -> dict:
    """Installed versions of the toolkit and its main dependencies ("?" when unknown)."""
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for pkg in ("stewart-drake", "drake", "numpy", "scipy", "matplotlib"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "?"
    return out


def git_commit(directory: Path) -> str | None:
    """``<hash>`` (plus " (modified)" for a dirty tree) of the checkout holding ``directory``, or None."""
    try:
        run = lambda *a: subprocess.run(["git", "-C", str(directory), *a], capture_output=True, text=True, timeout=10)  # noqa: E731
        head = run("rev-parse", "--short=12", "HEAD")
        if head.returncode != 0:
            return None
        dirty = run("status", "--porcelain", "--untracked-files=no").stdout.strip()
        return head.stdout.strip() + (" (modified)" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return None


def meta_html(meta: dict) -> str:
    """The header block: a two-column table of ``meta`` (keys in insertion order)."""
    rows = "".join(
        f"<tr><th>{html.escape(k)}</th><td>{html.escape(str(v))}</td></tr>"
        for k, v in meta.items()
        if v not in (None, "")
    )
    return f'<div class="scroll meta"><table>{rows}</table></div>'


def default_meta(sections, command: str | None = None, elapsed: float | None = None, presets=()) -> dict:
    from stewart_drake.report import ANALYSES_DIR  # the checkout the analyses came from

    v = versions()
    mode = "quick (small samples)" if any(s.quick for s in sections) else "full"
    return {
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "toolkit": f"stewart-drake {v.pop('stewart-drake')}",
        "dependencies": ", ".join(f"{k} {x}" for k, x in v.items()),
        "git commit": git_commit(ANALYSES_DIR) or "not a git checkout",
        "command": command,
        "mode": mode,
        "presets": ", ".join(presets),
        "run time": None if elapsed is None else f"{elapsed:.0f} s",
    }


def headline(section) -> str:
    """The section's one headline figure: its first failed check, else what the analysis set, else its
    tightest check (largest worst/tolerance), else nothing."""
    failed = [c for c in section.checks if not c.passed]
    if failed:
        c = failed[0]
        more = f" (and {len(failed) - 1} more)" if len(failed) > 1 else ""
        return f"FAILED: {c.what}: {format_number(c.worst)} > {format_number(c.tolerance)} {c.unit}".rstrip() + more
    if getattr(section, "headline_text", ""):
        return section.headline_text
    ratios = [
        (c.worst / c.tolerance if c.tolerance > 0 else (-1.0 if c.worst <= 0 else math.inf), c)
        for c in section.checks
        if not math.isnan(c.worst)
    ]
    if not ratios:
        return ""
    _, c = max(ratios, key=lambda rc: rc[0])
    if c.tolerance <= 0 and c.worst <= 0:
        return f"{c.what}: {format_number(c.worst)} {c.unit}".rstrip()
    return f"tightest: {c.what}: {format_number(c.worst)} of {format_number(c.tolerance)} {c.unit}".rstrip()


def verdicts_html(sections, anchor: dict) -> str:
    rows = []
    for s in sections:
        n, ok = len(s.checks), sum(c.passed for c in s.checks)
        cls = "pass" if ok == n else "fail"
        t = getattr(s, "elapsed", None)
        rows.append(
            f'<tr><td><a href="#{anchor[id(s)]}">{html.escape(s.title)}</a></td>'
            f'<td class="num {cls if n else ""}">{f"{ok}/{n}" if n else "—"}</td>'
            f"<td>{html.escape(headline(s))}</td><td class=num>{'' if t is None else f'{t:.1f}'}"
            f"{' (cached)' if getattr(s, 'cached', False) else ''}</td></tr>"
        )
    return (
        '<div class="scroll"><table class="verdicts"><thead><tr><th>section</th><th class=num>checks passed</th>'
        '<th>headline</th><th class=num>time <span class="unit">[s]</span></th></tr></thead><tbody>'
        + "".join(rows)
        + "</tbody></table></div>"
    )


def checks_html(sections, anchor: dict) -> str:
    """Every check, grouped by section in collapsible blocks (open where one fails)."""
    out = []
    for s in sections:
        if not s.checks:
            continue
        n, ok = len(s.checks), sum(c.passed for c in s.checks)
        rows = "".join(
            f"<tr><td>{html.escape(c.what)}</td>{cell(c.worst, 'not measured')[0]}{cell(c.tolerance)[0]}<td>{html.escape(c.unit)}</td>"
            f"<td class='{'pass' if c.passed else 'fail'}'>{'pass' if c.passed else 'FAIL'}</td></tr>"
            for c in s.checks
        )
        out.append(
            f"<details{' open' if ok < n else ''}><summary><a href='#{anchor[id(s)]}'>{html.escape(s.title)}</a>"
            f"<span class='{'pass' if ok == n else 'fail'}'>{ok}/{n}</span></summary>"
            '<div class="scroll"><table><thead><tr><th>what was compared</th><th class=num>worst</th><th class=num>tolerance</th>'
            f"<th>unit</th><th>result</th></tr></thead><tbody>{rows}</tbody></table></div></details>"
        )
    return "".join(out)


def render_html(sections, title: str, meta: dict) -> str:
    checks = [c for s in sections for c in s.checks]
    n_fail = sum(not c.passed for c in checks)
    anchor = {id(s): f"s{i}" for i, s in enumerate(sections)}
    body = "".join(
        f'<section id="s{i}"><h2>{html.escape(s.title)}</h2>{"".join(s.blocks)}</section>'
        for i, s in enumerate(sections)
    )
    status = f"<span class='{'fail' if n_fail else 'pass'}'>{len(checks) - n_fail}/{len(checks)} checks passed</span>"
    return (
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><meta name='viewport' content='width=device-width'>"
        f"<title>{html.escape(title)}</title><style>{CSS}</style></head><body>"
        f"<h1>{html.escape(title)}</h1>{meta_html(meta)}"
        f"<h2>Verdict</h2><p>{status} in {len(sections)} sections.</p>{verdicts_html(sections, anchor)}"
        f"<h2>All checks</h2>{checks_html(sections, anchor)}{body}</body></html>"
    )


_POINTS3D_JS = """
(function () {
  const c = document.getElementById(%(id)s), g = c.getContext("2d"), P = %(points)s, L = %(labels)s;
  let yaw = -0.6, pitch = 0.45, drag = null;
  const lo = [0, 1, 2].map(k => Math.min(...P.map(p => p[k]))), hi = [0, 1, 2].map(k => Math.max(...P.map(p => p[k])));
  const mid = lo.map((v, k) => (v + hi[k]) / 2), span = Math.max(...hi.map((v, k) => v - lo[k])) || 1;
  function proj(p) {
    const x = (p[0] - mid[0]) / span, y = (p[1] - mid[1]) / span, z = (p[2] - mid[2]) / span;
    const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
    const x1 = cy * x - sy * y, y1 = sy * x + cy * y;
    return [x1, cp * z - sp * y1, sp * z + cp * y1];
  }
  function draw() {
    const w = c.width, h = c.height, s = 0.62 * Math.min(w, h);
    g.fillStyle = "#fff"; g.fillRect(0, 0, w, h);
    const q = P.map(p => [proj(p), p[2]]).sort((a, b) => b[0][2] - a[0][2]);
    for (const [r, z] of q) {
      const t = (z - lo[2]) / ((hi[2] - lo[2]) || 1);
      g.fillStyle = `hsl(${260 - 200 * t}, 70%%, ${35 + 20 * t}%%)`;
      g.fillRect(w / 2 + s * r[0] - 1, h / 2 - s * r[1] - 1, 2.2, 2.2);
    }
    g.font = "13px sans-serif";
    [[0, "#c00"], [1, "#080"], [2, "#00c"]].forEach(([k, col]) => {
      const e = [0, 0, 0]; e[k] = 0.35 * span;
      const a = proj(mid.map((m, i) => i === k ? m : m)), b = proj(mid.map((m, i) => m + e[i]));
      const ox = w * 0.12, oy = h * 0.85;
      g.strokeStyle = col; g.fillStyle = col; g.beginPath(); g.moveTo(ox, oy);
      g.lineTo(ox + s * (b[0] - a[0]) * 0.6, oy - s * (b[1] - a[1]) * 0.6); g.stroke();
      g.fillText(L[k], ox + s * (b[0] - a[0]) * 0.7, oy - s * (b[1] - a[1]) * 0.7);
    });
  }
  c.onpointerdown = e => { drag = [e.clientX, e.clientY]; try { c.setPointerCapture(e.pointerId); } catch (_) {} };
  c.onpointermove = e => { if (!drag) return; yaw += (e.clientX - drag[0]) * 0.01;
    pitch = Math.max(-1.5, Math.min(1.5, pitch + (e.clientY - drag[1]) * 0.01)); drag = [e.clientX, e.clientY]; draw(); };
  c.onpointerup = () => { drag = null; };
  draw();
})();
"""


def points3d_html(
    element_id: str, points, labels=("x [m]", "y [m]", "z [m]"), caption: str = "", max_points: int = 4000
) -> str:
    """A rotatable 3-D point cloud (drag to turn) drawn by inline JavaScript on a canvas: no library, so
    the page stays one self-contained file. ``points`` ``(n, 3)``; at most ``max_points`` kept (seeded)."""
    import json

    P = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(P) > max_points:
        P = P[np.random.default_rng(0).choice(len(P), max_points, replace=False)]
    js = _POINTS3D_JS % {
        "id": json.dumps(element_id),
        "points": json.dumps(np.round(P, 5).tolist()),
        "labels": json.dumps(list(labels)),
    }
    cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
    return (
        f'<figure><canvas id="{html.escape(element_id)}" width="640" height="480" class="points3d" '
        f'style="max-width:100%;border:1px solid #ddd;cursor:grab;touch-action:none"></canvas>{cap}<script>{js}</script></figure>'
    )
