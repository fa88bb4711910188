"""The report, the Meshcat animation and the viewer, opened in headless Chromium (DevTools protocol):
no console errors, no horizontal overflow at 1280 px, every image loaded, a canvas that is not blank,
and a viewer slider that moves the displayed leg lengths. Skipped, with the reason, without Chromium
(``scripts/ensure-chromium`` installs it)."""

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.report.browser import Browser, find_chromium

pytestmark = pytest.mark.skipif(
    find_chromium() is None, reason="Chromium or websocket-client not installed: run scripts/ensure-chromium"
)

ROOT = Path(__file__).resolve().parents[2]
WIDTH = 1280
SHOTS = os.environ.get("STEWART_SCREENSHOTS")  # a folder: also save the screenshots there


def _shot(name):
    return None if not SHOTS else Path(SHOTS) / name


@pytest.fixture(scope="module")
def browser():
    with Browser(width=WIDTH, height=900) as b:
        yield b


def _report(tmp_path):
    """A report built by the real pipeline from two quick analyses (one with a wide table and figures)."""
    from stewart_drake.report import discover_analyses, render, run_analyses, write_report

    sections = run_analyses(discover_analyses(only=["seed_table", "leg"]), quick=True)
    # One section with the shapes the framework must handle: a wide table, a NaN, units written three ways.
    from stewart_drake.report import Section

    s = Section("Framework shapes", quick=True)
    s.table([f"column {k} [mm]" for k in range(24)], [[float(k) * 1.2345 for k in range(24)]], caption="a wide table")
    s.table(
        ["case", "first saturation s", "force (N)", "count"],
        [["a", float("nan"), 200.0, 1], ["b", 0.286, 3.5e-7, 12]],
        nan_reason="never saturated",
    )
    s.check("a passing check", 0.5, 1.0, "mm")
    u = np.random.default_rng(0).normal(size=(3000, 3))
    s.points3d(0.3 * u / np.linalg.norm(u, axis=1, keepdims=True), "sphere", "points on a sphere")
    sections.append(s)
    return write_report(
        sections, tmp_path / "report", meta=render.default_meta(sections, "pytest", 0.0, ("utn-dynamic",))
    )


def test_report_renders_cleanly(browser, tmp_path):
    index = _report(tmp_path)
    browser.errors.clear()
    browser.open(str(index))
    assert browser.errors == []
    # No horizontal overflow: the page is no wider than the window (wide tables scroll in their box).
    assert browser.evaluate("document.documentElement.scrollWidth") <= WIDTH
    images = browser.evaluate("Array.from(document.images).map(i => [i.complete, i.naturalWidth])")
    assert images and all(ok and w > 0 for ok, w in images)
    # Text cells left, number cells right; NaN shown as a dash with its reason, never "nan".
    aligns = browser.evaluate("""(() => { const t = document.querySelectorAll('section table')[document.querySelectorAll('section table').length - 1];
        return Array.from(t.querySelectorAll('tbody tr:first-child td')).map(td => getComputedStyle(td).textAlign); })()""")
    assert aligns[0] in ("left", "start") and aligns[2] == "right" and aligns[3] == "right"
    text = browser.evaluate("document.body.innerText")
    assert not re.search(r"\bnan\b", text) and "never saturated" in text
    # The header and the verdicts come first; the checks are grouped in collapsible blocks.
    assert browser.evaluate("document.querySelectorAll('details').length") >= 3
    assert "git commit" in text and "command" in text
    # The rotatable 3-D view draws points, and dragging turns it (the pixels change).
    pixels = """(() => { const c = document.getElementById('p3d-sphere'); const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0, h = 0; for (let i = 0; i < d.length; i += 4) { if (d[i] + d[i + 1] + d[i + 2] < 600) { n++; h = (h * 31 + i) % 1000003; } } return [n, h]; })()"""
    before = browser.evaluate(pixels)
    assert before[0] > 2000
    browser.evaluate("""(() => { const c = document.getElementById('p3d-sphere'); const r = c.getBoundingClientRect();
        const ev = (t, x) => c.dispatchEvent(new PointerEvent(t, {clientX: r.left + x, clientY: r.top + 100, pointerId: 1, bubbles: true}));
        ev('pointerdown', 100); ev('pointermove', 160); ev('pointerup', 160); return 1; })()""")
    assert browser.evaluate(pixels) != before
    assert browser.errors == []
    browser.screenshot(_shot("report_top.png"))
    browser.evaluate("document.querySelector('section').scrollIntoView(); 1")
    browser.screenshot(_shot("report_section.png"))


def _animation_html(tmp_path):
    from stewart_drake.drake.animation import record_animation

    p = load_preset("utn-dynamic")
    t = np.linspace(0.0, 1.0, 1001)
    poses = np.tile(p.home_pose(), (len(t), 1))
    # Rise until the legs come within the warning band of L_max around t = 0.5 s.
    poses[:, 2] += 0.23 * np.sin(np.pi * t)
    path = tmp_path / "animation.html"
    path.write_text(record_animation(p, t, poses, title="test"), encoding="utf-8")
    return path, p, t, poses


def _empty_scene(tmp_path):
    from pydrake.geometry import Meshcat, MeshcatParams

    path = tmp_path / "empty.html"
    path.write_text(Meshcat(MeshcatParams(host="localhost")).StaticHtml(), encoding="utf-8")
    return path


def test_animation_canvas_is_not_blank_and_legs_warn(browser, tmp_path):
    path, p, t, poses = _animation_html(tmp_path)
    browser.errors.clear()
    browser.open(str(_empty_scene(tmp_path)), settle=1.0)
    empty = browser.screenshot()
    browser.open(str(path), settle=1.0)
    browser.wait_for("typeof viewer !== 'undefined' && viewer.animator.duration > 0")
    browser.evaluate("viewer.animator.pause(); viewer.animator.seek(0.5); 1")
    browser.wait_for("document.getElementById('sd-time').textContent === 't = 0.50 s'")
    img = browser.screenshot(_shot("animation.png"))
    assert browser.errors == []
    # The platform occupies the middle of the view: many pixels there differ from the empty scene.
    h, w = img.shape[:2]
    centre = (slice(h // 4, 3 * h // 4), slice(w // 3, 2 * w // 3))
    changed = np.abs(img[centre][..., :3] - empty[centre][..., :3]).max(axis=-1) > 0.1
    assert changed.mean() > 0.05, f"only {changed.mean():.1%} of the centre differs from an empty scene"
    # At t = 0.5 s every leg is within 5 % of L_max: its warning sleeve is visible; at t = 0 none is.
    L = leg_lengths(p, poses[np.searchsorted(t, 0.5)])
    assert (p.L_max - L < 0.05 * (p.L_max - p.L_min)).all()
    sleeve = "viewer.scene_tree.find(['drake','visualizer','utn-dynamic','cylinder_1','warning']).object.visible"
    assert browser.evaluate(sleeve) is True
    browser.evaluate("viewer.animator.seek(0.0); 1")
    browser.wait_for(f"!{sleeve}", timeout=5)


LABELS = "Array.from(document.querySelectorAll('.dg .property-name')).map(e => e.textContent)"


def _set_slider(browser, name, value):
    browser.evaluate(f"""(() => {{ const li = Array.from(document.querySelectorAll('.dg li.cr'))
        .find(l => l.querySelector('.property-name').textContent === {name!r});
        const inp = li.querySelector('input'); inp.value = '{value}'; inp.dispatchEvent(new Event('change')); return 1; }})()""")


def test_viewer_slider_moves_the_leg_lengths(browser):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(
        [sys.executable, "-m", "stewart_drake.cli", "view", "--platform", "utn-dynamic", "--duration", "60"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=ROOT,
    )
    try:
        line = proc.stdout.readline()
        url = re.search(r"http://localhost:\d+", line)
        assert url, f"no URL in {line!r}: {proc.stderr.read() if proc.poll() is not None else ''}"
        browser.errors.clear()
        browser.open(url.group(0), settle=0.5)
        labels = browser.wait_for(f"{LABELS}.some(s => s.startsWith('L1 ')) && {LABELS}")
        p = load_preset("utn-dynamic")
        home = leg_lengths(p, p.home_pose())
        assert f"L1 {home[0] * 1e3:.1f} mm" in " ".join(labels)
        assert "pose reachable" in labels and any(s.startswith("assembly modes") for s in labels)
        browser.evaluate("document.querySelector('.dg.main .close-button').click(); 1")  # open the controls panel
        # Raise the plate 50 mm: the displayed L1 must become the closed-form length there.
        _set_slider(browser, "pz [mm]", 750)
        want = leg_lengths(p, p.home_pose() + [0, 0, 0.05, 0, 0, 0])[0] * 1e3
        browser.wait_for(f"{LABELS}.some(s => s.startsWith('L1 {want:.1f} mm'))", timeout=20)
        browser.screenshot(_shot("viewer.png"))
        # An unreachable pose is shown, legs red, the nearest reachable pose ghosted.
        _set_slider(browser, "pz [mm]", 1050)
        browser.wait_for(f"{LABELS}.some(s => s.startsWith('UNREACHABLE'))", timeout=20)
        assert browser.evaluate("viewer.scene_tree.find(['ghost','plate']).object.children.length > 0")
        browser.screenshot(_shot("viewer_unreachable.png"))
        assert browser.errors == []
    finally:
        proc.terminate()
        proc.wait(timeout=20)
