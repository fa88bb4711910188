"""The report's result cache (``report.cache``): a hit gives the section back exactly, without running the
analysis; a change of the package, of the analysis' script or of an input it declares is a miss; a script that
declares no inputs is never cached; ``--no-cache`` recomputes."""

from __future__ import annotations

import io
import json
import os

import pytest

from stewart_drake.cli import main
from stewart_drake.report import cache, discover_analyses, run_analyses

# An analysis that counts its runs in a file beside it and adds a check and a figure drawn from that count
# on its first run only, so a recomputed section would differ from the stored one if it were ever taken for it.
ANALYSIS = """
from pathlib import Path
import matplotlib.pyplot as plt
TITLE, ORDER = "counted", 1
INPUTS = []  # it reads no file but its own count (which the cache must ignore)
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


def test_a_new_package_version_or_script_is_a_miss(counted, monkeypatch):
    _run(counted)
    real = cache.package_version()
    monkeypatch.setattr(cache, "package_version", lambda: real[::-1])  # an edit of the package
    s, _ = _run(counted)
    assert _runs(counted) == 2 and not s.cached and s.checks[0].what == "run 2"
    monkeypatch.setattr(cache, "package_version", lambda: real)
    assert _run(counted)[0].cached  # the first version's entry is still there
    (counted / "counted.py").write_text(ANALYSIS + "\n# edited\n")  # an analysis outside the package: its own text
    s, _ = _run(counted)
    assert _runs(counted) == 3 and not s.cached


def test_package_version_follows_every_package_file_but_bytecode(tmp_path):
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "p.yaml").write_text("name: p\n")
    versions = [cache.package_version.__wrapped__(tmp_path)]
    (tmp_path / "data" / "p.yaml").write_text("name: q\n")  # data
    versions.append(cache.package_version.__wrapped__(tmp_path))
    (tmp_path / "a.py").write_text("x = 2\n")  # a source, whatever imports it
    versions.append(cache.package_version.__wrapped__(tmp_path))
    (tmp_path / "__pycache__").mkdir()
    (tmp_path / "__pycache__" / "a.cpython-312.pyc").write_bytes(b"\0")  # bytecode is not code
    assert len(set(versions)) == 3 and cache.package_version.__wrapped__(tmp_path) == versions[-1]


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


# Analyses of the user's that read files of their own in the three ways an audit of Python's reads misses or
# keys wrongly: through a symbolic link later retargeted, through a subprocess, and by listing a folder.
READERS = {
    "symlink": """
from pathlib import Path
TITLE, ORDER = "through a link", 1
def build(section):
    section.check("the value behind link.txt", float(Path(__file__).with_name("link.txt").read_text()), 10.0, "1")
""",
    "subprocess": """
import subprocess, sys
from pathlib import Path
TITLE, ORDER = "through a subprocess", 1
def build(section):
    data = Path(__file__).with_name("data.txt")
    out = subprocess.run([sys.executable, "-c", f"print(open({str(data)!r}).read())"], capture_output=True, text=True)
    section.check("the value in data.txt", float(out.stdout), 10.0, "1")
""",
    "listing": """
from pathlib import Path
TITLE, ORDER = "a folder's listing", 1
def build(section):
    section.check("files in listed/", len(list(Path(__file__).with_name("listed").iterdir())), 10.0, "1")
""",
}


@pytest.fixture
def readers(tmp_path, monkeypatch):
    """The three readers, each in its own folder with its data: ``{kind: (folder, change)}``, ``change()``
    altering what that reader reads without touching the file it names."""
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    out = {}
    for kind, text in READERS.items():
        d = tmp_path / kind
        d.mkdir()
        (d / f"{kind}.py").write_text(text)
        out[kind] = d
    (tmp_path / "symlink" / "a.txt").write_text("1")
    (tmp_path / "symlink" / "b.txt").write_text("2")
    os.symlink("a.txt", tmp_path / "symlink" / "link.txt")
    (tmp_path / "subprocess" / "data.txt").write_text("1")
    (tmp_path / "listing" / "listed").mkdir()
    (tmp_path / "listing" / "listed" / "one").write_text("")

    def retarget():
        (tmp_path / "symlink" / "link.txt").unlink()
        os.symlink("b.txt", tmp_path / "symlink" / "link.txt")

    changes = {
        "symlink": retarget,
        "subprocess": lambda: (tmp_path / "subprocess" / "data.txt").write_text("2"),
        "listing": lambda: (tmp_path / "listing" / "listed" / "two").write_text(""),
    }
    return {kind: (out[kind], changes[kind]) for kind in READERS}


@pytest.mark.parametrize("kind", sorted(READERS))
def test_a_section_reading_undeclared_files_is_never_cached(readers, kind):
    folder, change = readers[kind]
    first, _ = _run(folder)
    again, _ = _run(folder)
    assert first.checks[0].worst == again.checks[0].worst == 1.0 and not again.cached
    change()
    s, _ = _run(folder)
    assert not s.cached and s.checks[0].worst == 2.0  # what it reads now, never a stale section


@pytest.mark.parametrize("kind,declared", [("symlink", "link.txt"), ("subprocess", "data.txt"), ("listing", "listed")])
def test_a_declared_input_keys_the_section(readers, kind, declared):
    """The same readers declaring what they read: cached while it is unchanged, recomputed when it changes (the
    link's target's content, the file a subprocess read, a file added to the listed folder)."""
    folder, change = readers[kind]
    script = folder / f"{kind}.py"
    script.write_text(script.read_text() + f"INPUTS = [{declared!r}]\n")
    first, _ = _run(folder)
    assert not first.cached and _run(folder)[0].cached  # unchanged: served from the cache
    change()
    s, _ = _run(folder)
    assert not s.cached and s.checks[0].worst == 2.0 and _run(folder)[0].cached


def test_a_package_analysis_is_cached(tmp_path, monkeypatch):
    """A package analysis reads the package and its subject only, both in its key: served from the cache."""
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    (a,) = discover_analyses(only=["seed_table"])
    assert cache.section_key(a, True) is not None and cache.section_key(a, True) == cache.section_key(a, True)
    assert cache.section_key(a, True) != cache.section_key(a, False)
