"""The report's shared pool (``report.parts``): an analysis's declared parts run once, as tasks of the
report's own workers, and its section gets their results instead of computing them again."""

import io
from concurrent.futures import Future
from types import SimpleNamespace

from stewart_drake.report import discover_analyses, parallel_map, parts, run_analyses

ANALYSIS = """
from pathlib import Path
from stewart_drake.report import parallel_map

TITLE = "with parts"
ORDER = 1
COST = 10
LOG = Path({log!r})


def parts(quick):
    return [("square", k) for k in range(4)]


def square(k):
    with open(LOG, "a") as f:  # one line per computation
        f.write(f"{{k}}\\n")
    return k * k


def build(section):
    got = parallel_map(__file__, "square", list(range(4)))
    section.check("parts' results in order", float(got != [0, 1, 4, 9]), 0.0)
"""


def test_parts_run_once_in_the_report_pool(tmp_path):
    # Before, a section fanned its cases out to a pool of its own inside a report worker; now the report's
    # pool runs them (once each) and the section's parallel_map gives their results back.
    log = tmp_path / "calls.txt"
    (tmp_path / "a.py").write_text(ANALYSIS.format(log=str(log)))
    (tmp_path / "b.py").write_text(
        "TITLE = 'plain'\nORDER = 2\ndef build(section):\n    section.check('ran', 0.0, 1.0)\n"
    )
    out = io.StringIO()
    sections = run_analyses(discover_analyses(tmp_path), jobs=2, log=out)
    assert [s.title for s in sections] == ["with parts", "plain"]
    assert all(c.passed for s in sections for c in s.checks)
    assert sorted(log.read_text().split()) == ["0", "1", "2", "3"]  # each part computed once, none again
    assert sections[0].parts == 4 and "4 parts in the shared pool" in out.getvalue()


def test_parts_without_the_report_are_computed_by_the_section(tmp_path):
    # jobs=1 (a standalone run): no precomputed parts; parallel_map computes them itself
    log = tmp_path / "calls.txt"
    (tmp_path / "a.py").write_text(ANALYSIS.format(log=str(log)))
    (s,) = run_analyses(discover_analyses(tmp_path), jobs=1, log=io.StringIO())
    assert all(c.passed for c in s.checks) and sorted(log.read_text().split()) == ["0", "1", "2", "3"]
    # a one-item map runs in this process, which stays a parent: a later map here may start its pool
    assert parallel_map(str(tmp_path / "a.py"), "square", [3]) == [9] and not parts.IN_WORKER


class _Inline:
    """A pool that runs each task when submitted, recording the order."""

    def __init__(self):
        self.order = []

    def submit(self, fn, *args):
        f = Future()
        if fn is parts.run_part:
            self.order.append(("part", args[0], args[2]))
            f.set_result((args[2], 0.5, 0.25))
        else:
            self.order.append(("section", args[0]))
            f.set_result(args[2])
        return f


def test_schedule_costliest_first_and_a_section_right_after_its_parts():
    analyses = [
        SimpleNamespace(path="cheap", cost=1.0, parts=None),
        SimpleNamespace(path="heavy", cost=50.0, parts=lambda quick: [("f", 1), ("f", 2)]),
        SimpleNamespace(path="middle", cost=5.0, parts=lambda quick: [("f", 3)]),
    ]
    pool, got = _Inline(), {}
    parts.schedule(
        pool,
        analyses,
        False,
        1,
        lambda path, quick, done, subject: done,
        lambda i, f, w, c, n: got.update({i: (f.result(), w, c, n)}),
    )
    assert pool.order == [
        ("part", "heavy", 1),
        ("part", "heavy", 2),
        ("section", "heavy"),
        ("part", "middle", 3),
        ("section", "middle"),
        ("section", "cheap"),
    ]
    # each section got its own parts' results, keyed by (script, function, item), and their time summed
    assert got[1][0] == {parts.part_key("heavy", "f", 1): 1, parts.part_key("heavy", "f", 2): 2}
    assert got[1][1:4] == (1.0, 0.5, 2) and got[0] == ({}, 0.0, 0.0, 0)
