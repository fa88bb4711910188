"""Report rendering: number and unit formatting, tables, the header and verdicts, the axis-label lint,
and analyses run in worker processes coming back in order."""

import math
import re

import matplotlib.pyplot as plt
import pytest

from stewart_drake.report import Section, discover_analyses, render, run_analyses, unlabelled_axes


@pytest.mark.parametrize(
    "v, text",
    [
        (0.286, "0.2860"),
        (1.0, "1.000"),
        (200.0, "200.0"),
        (1234.5678, "1235"),
        (9.99996, "10.00"),
        (-0.0123456, "−0.01235"),
        (3.5e-7, "3.500e−07"),
        (946000.0, "9.460e+05"),
        (0.0, "0"),
        (7, "7"),
        (float("inf"), "∞"),
    ],
)
def test_format_number_significant_digits(v, text):
    assert render.format_number(v) == text


def test_format_number_reads_back():
    # Four significant digits: the printed value is within half a unit in the 4th digit of the input.
    for v in (0.001234567, 0.9876543, 12.34567, 98765.4, 123456.7, 2.5e-9):
        s = render.format_number(v).replace("−", "-")
        assert abs(float(s) - v) <= 0.5 * 10 ** (math.floor(math.log10(abs(v))) - 3) * (1 + 1e-12)


@pytest.mark.parametrize(
    "header, split",
    [
        ("max |leg err| mm", ("max |leg err|", "mm")),
        ("position error (mm)", ("position error", "mm")),
        ("X [m]", ("X", "m")),
        ("ki N/(m·s)", ("ki", "N/(m·s)")),
        ("preset", ("preset", "")),
        ("(fixed − float)/(Δ_IK + LSB + r)", ("(fixed − float)/(Δ_IK + LSB + r)", "")),
        ("saturated ticks", ("saturated ticks", "")),
    ],
)
def test_units_written_alike(header, split):
    assert render.split_unit(header) == split


def test_table_cells():
    html = render.table_html(
        ["case", "first saturation s", "force (N)"],
        [["a", float("nan"), 200.0], ["b", 0.286, "1.5"]],
        nan_reason="never saturated",
    )
    assert 'class="scroll"' in html  # wide tables scroll in their box
    assert "nan" not in html.lower().replace("never saturated", "")
    assert "— <small>(never saturated)</small>" in html
    assert '<td class="num">200.0</td>' in html and '<td class="num">1.5</td>' in html
    assert re.search(r"<th class=num>force <span class=\"unit\">\[N\]</span></th>", html)
    assert "<td class=nw>a</td>" in html


def test_unlabelled_axes_lint():
    fig, (a, b) = plt.subplots(1, 2)
    a.plot([0, 1], [0, 1])
    a.set_xlabel("t [s]")
    b.plot([0, 1], [1, 0])
    b.set_xlabel("t [s]"), b.set_ylabel("L [m]")
    fig.colorbar(b.scatter([0, 1], [0, 1], c=[0, 1]), ax=b)  # a colorbar's own axes need no label
    problems = unlabelled_axes(fig)
    plt.close(fig)
    assert problems == ["axes 0 (untitled) has no y label"]


def _write_analysis(folder, name, order, sleep):
    (folder / f"{name}.py").write_text(
        f"import time\nTITLE = {name!r}\nORDER = {order}\n"
        f"def build(section):\n    time.sleep({sleep})\n    section.check('ran', 0.0, 1.0, 's')\n    section.headline('{name} headline')\n"
    )


def test_parallel_analyses_keep_their_order(tmp_path):
    # The first analysis is the slowest: it finishes last, yet its section stays first.
    _write_analysis(tmp_path, "a_slow", 1, 1.0)
    _write_analysis(tmp_path, "b_fast", 2, 0.0)
    _write_analysis(tmp_path, "c_fast", 3, 0.0)
    import io

    log = io.StringIO()
    sections = run_analyses(discover_analyses(tmp_path), jobs=2, log=log)
    assert [s.title for s in sections] == ["a_slow", "b_fast", "c_fast"]
    assert all(s.elapsed is not None for s in sections) and sections[0].elapsed >= 1.0
    lines = log.getvalue().splitlines()
    # numbered in the report's order (a_slow is section 1, finished third), not in completion order (issue 24, 9)
    assert len(lines) == 3 and lines[-1].startswith("[section 1/3, 3 done] a_slow: 1/1 checks passed")

    page = render.render_html(
        sections, "t", render.default_meta(sections, "stewart-drake report", 1.0, ("utn-dynamic",))
    )
    assert page.index("Verdict") < page.index("All checks") < page.index('<section id="s0">')
    assert "a_slow headline" in page and "stewart-drake report" in page and "utn-dynamic" in page


def test_progress_titles_are_cut_at_a_word(tmp_path):
    """A long title was cut mid-word ("…driving the clo"): now shortened at a word, with an ellipsis."""
    import io

    title = "Controller in the loop: the fixed-point DSP controller driving the closed-loop plant"
    (tmp_path / "long.py").write_text(
        f"TITLE = {title!r}\nORDER = 1\ndef build(section):\n    section.check('ran', 0.0, 1.0)\n"
    )
    log = io.StringIO()
    run_analyses(discover_analyses(tmp_path), log=log)
    assert log.getvalue().startswith(
        "[section 1/1] Controller in the loop: the fixed-point DSP controller driving the …: 1/1 checks passed"
    )


def test_tightest_check_is_the_default_headline():
    s = Section("x")
    s.check("loose", 1.0, 100.0, "mm")
    s.check("tight", 0.9, 1.0, "mm")
    assert render.headline(s) == "tightest: tight: 0.9000 of 1.000 mm"
    s.check("broken", 2.0, 1.0, "mm")
    assert render.headline(s) == "FAILED: broken: 2.000 > 1.000 mm"
