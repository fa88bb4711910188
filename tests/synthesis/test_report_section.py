"""The report's "Design synthesis" section on seed 001's requirements (quick): the synthesised design is proven
over the whole box (its stroke, and its force, speed, frequency and condition number: the performance proof's
bounds dominate 10⁴ sampled poses), meets every requirement, and has a smaller peak force or stroke than the paper's geometry."""

from __future__ import annotations

from stewart_drake.analyses import synthesis
from stewart_drake.report import Section


def test_section_checks_pass_quick():
    s = Section(synthesis.TITLE, quick=True)
    synthesis.build(s)
    checks = {c.what: c for c in s.checks}
    assert len(checks) == 7 and all(c.passed for c in s.checks), [(c.what, c.worst) for c in s.checks]
    ratio = checks["synthesised / paper: the smaller of peak force ratio and stroke ratio"].worst
    assert ratio < 1.0  # smaller force or stroke than the paper's geometry
    assert "synthesis_pareto.png" in s.files and "vs the paper's 400 mm" in s.headline_text
