"""The report's result cache (``report.cache``): a hit gives the section back exactly, without running the
analysis; a change of the code version or of the analysis' script is a miss; ``--no-cache`` recomputes."""

from __future__ import annotations

import hashlib
import io
import json

import pytest

from stewart_drake.cli import main
from stewart_drake.report import cache, discover_analyses, run_analyses

# An analysis that counts its runs in a file beside it and adds a check and a figure drawn from that count
# on its first run only, so a recomputed section would differ from the stored one if it were ever taken for it.
ANALYSIS = """
from pathlib import Path
import matplotlib.pyplot as plt
TITLE, ORDER = "counted", 1
RUNS = Path(__file__).with_suffix(".runs")
def build(section):
    n = int(RUNS.read_text()) + 1 if RUNS.exists() else 1
    RUNS.write_text(str(n))
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, n])
    ax.set_xlabel("x [1]")
    ax.set_ylabel("run [1]")
    section.figure(fig, "counted", "the run count")
    section.check(f"run {n}", n * 0.5, 10.0, "1")
"""


@pytest.fixture
def counted(tmp_path, monkeypatch):
    """The counting analysis in its own folder, with a fresh cache folder."""
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    d = tmp_path / "analyses"
    d.mkdir()
    (d / "counted.py").write_text(ANALYSIS)
    return d


def _run(folder, use_cache=True):
    log = io.StringIO()
    (s,) = run_analyses(discover_analyses(folder), quick=True, log=log, cache=use_cache)
    return s, log.getvalue()


def _runs(folder) -> int:
    return int((folder / "counted.runs").read_text())


def test_a_hit_gives_the_section_back_exactly_without_running_it(counted):
    first, log1 = _run(counted)
    again, log2 = _run(counted)
    assert _runs(counted) == 1  # the second report did not run the analysis
    assert not first.cached and again.cached and "from the cache" in log2 and "from the cache" not in log1
    assert [c.__dict__ for c in again.checks] == [c.__dict__ for c in first.checks]
    assert again.files == first.files and again.blocks == first.blocks  # the figure's PNG bytes included
    assert (again.elapsed, again.cpu) == (first.elapsed, first.cpu)  # the time it took when computed


def test_a_new_code_version_or_script_is_a_miss(counted, monkeypatch):
    _run(counted)
    real = cache.code_version((counted / "counted.py").resolve())
    monkeypatch.setattr(cache, "code_version", lambda path: real[::-1])  # an edit of the code it runs
    s, _ = _run(counted)
    assert _runs(counted) == 2 and not s.cached and s.checks[0].what == "run 2"
    monkeypatch.setattr(cache, "code_version", lambda path: real)
    assert _run(counted)[0].cached  # the first version's entry is still there
    (counted / "counted.py").write_text(ANALYSIS + "\n# edited\n")  # an analysis outside the package: its own text
    s, _ = _run(counted)
    assert _runs(counted) == 3 and not s.cached


def test_data_version_follows_every_package_data_file(tmp_path):
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "p.yaml").write_text("name: p\n")
    v0 = cache.data_version.__wrapped__(tmp_path)
    (tmp_path / "data" / "p.yaml").write_text("name: q\n")
    cache._package_digest.cache_clear()
    v1 = cache.data_version.__wrapped__(tmp_path)
    (tmp_path / "__pycache__").mkdir()
    (tmp_path / "__pycache__" / "a.cpython-312.pyc").write_bytes(b"\0")
    (tmp_path / "a.py").write_text("x = 2\n")  # a source: in the versions of the sections that reach it
    assert v0 != v1 == cache.data_version.__wrapped__(tmp_path)  # bytecode is not code


def test_no_cache_recomputes_and_a_crash_is_not_stored(counted):
    _run(counted)
    s, _ = _run(counted, use_cache=False)
    assert _runs(counted) == 2 and not s.cached
    (counted / "counted.py").write_text(ANALYSIS + "    raise RuntimeError('flaky')\n")
    for n in (3, 4):  # a failed analysis is tried again next time
        s, _ = _run(counted)
        assert s.crashed and not s.cached and _runs(counted) == n


def test_report_command_no_cache(tmp_path, monkeypatch, capsys):
    """``stewart-drake report``: the second run takes the sections from the cache with the same checks;
    ``--no-cache`` computes them again."""
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    argv = ["report", "--only", "seed_table", "--quick", "--jobs", "1"]
    logs = []
    for k, extra in enumerate(([], [], ["--no-cache"])):
        assert main([*argv, "--out", str(tmp_path / f"r{k}"), *extra]) == 0
        logs.append(capsys.readouterr().err)
    checks = [json.loads((tmp_path / f"r{k}" / "checks.json").read_text()) for k in range(3)]
    assert checks[0] == checks[1] == checks[2] and checks[0]
    assert ["from the cache" in e for e in logs] == [False, True, False]
    # the first line says what runs where: nothing runs on the second
    assert [e.splitlines()[0] for e in logs] == [
        "running 1 analysis in this process",
        "running 0 analyses in this process, 1 from the cache",
        "running 1 analysis in this process",
    ]
    assert (tmp_path / "r0" / "seed_table_matlab.png").read_bytes() == (
        tmp_path / "r1" / "seed_table_matlab.png"
    ).read_bytes()


# An analysis of the user's that reads a file of its own (its platform, say): the file is an input of its section.
READER = """
from pathlib import Path
import stewart_drake
TITLE, ORDER = "reader", 1
DATA = Path(__file__).with_name("data.txt")
def build(section):
    stewart_drake.load_platform("utn-dynamic")  # a package file read: keyed by the code version, not recorded
    section.check("the value in data.txt", float(DATA.read_text()), 10.0, "1")
"""


def test_a_file_the_section_read_is_an_input(tmp_path, monkeypatch):
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    d = tmp_path / "analyses"
    d.mkdir()
    (d / "reader.py").write_text(READER)
    (d / "data.txt").write_text("1.5")
    first, _ = _run(d)
    assert first.inputs == {str((d / "data.txt").resolve()): hashlib.sha256(b"1.5").hexdigest()}
    assert _run(d)[0].cached
    (d / "data.txt").write_text("2.5")  # edited: computed again, with the new value
    s, _ = _run(d)
    assert not s.cached and s.checks[0].worst == 2.5 and _run(d)[0].cached
    (d / "data.txt").unlink()  # removed: computed again (and it fails, saying why)
    s, _ = _run(d)
    assert not s.cached and s.crashed
