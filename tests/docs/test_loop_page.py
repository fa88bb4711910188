"""The page "Designing the loop" says what the section finds, and the site shows its three figures, drawn at build
time from the 210 kg example machine (``scripts/docs_hooks.py``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.analyses import the_loop
from stewart_drake.report.subject import from_machine_file, machine_of

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "designing-the-loop.md"
FIGURES = ("loop-margins.png", "loop-bode.png", "loop-ripple.png")


def test_the_page_shows_the_three_figures_the_build_draws(site):
    out, _ = site
    html = (out / "designing-the-loop.html").read_text(encoding="utf-8")
    for name in FIGURES:
        assert f'src="img/{name}"' in html, name
        assert (out / "img" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name


def test_the_pages_findings_hold():
    """The page: the 210 kg machine, with the gains designed over its rotating motion, is unstable at ±15° of roll
    and of pitch and nowhere else on the grid; gonzalez-dutra-2009's designed gains keep about 1 dB and 4°."""
    text = PAGE.read_text(encoding="utf-8")
    assert "unstable at ±15° of roll and of pitch" in text and "about 1 dB and 4°" in text
    subject = from_machine_file(ROOT / "examples" / "newcomer-210kg.yaml")
    base = machine_of(subject)
    machine = the_loop.chosen_machine(base, the_loop.motion(base, subject))
    rows = the_loop.workspace_margins(machine)
    assert the_loop.motion(base, subject).name == "rotating"
    assert sorted(r["pose"] for r in rows if r["rho"] >= 1) == ["α+", "α−", "β+", "β−"]
    gd = the_loop.workspace_margins(the_loop._study_machine("gonzalez-dutra-2009")[0])
    gm, pm = min(r["gm"] for r in gd), min(r["pm"] for r in gd)
    assert np.round(gm) == 1 and np.round(pm) == 4
