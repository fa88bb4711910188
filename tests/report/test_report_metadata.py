"""``report.metadata``: the report's parent reads each analysis's TITLE/ORDER/COST and whether it declares
``parts`` from the source, the same values the imported script holds, and imports nothing."""

from __future__ import annotations

import importlib
import io

from stewart_drake.report import ANALYSES_DIR, FromScript, discover_analyses, metadata, run_analyses


def test_the_source_gives_what_the_import_holds():
    scripts = sorted(p for p in ANALYSES_DIR.glob("*.py") if not p.name.startswith("_"))
    assert len(scripts) >= 10
    for p in scripts:
        meta = metadata.read(p)
        assert meta is not None, p.name  # every analysis of the package is read without importing it
        mod = importlib.import_module(f"stewart_drake.analyses.{p.stem}")
        assert (meta["TITLE"], meta["ORDER"], meta["COST"]) == (mod.TITLE, mod.ORDER, getattr(mod, "COST", 0.0))
        assert meta["parts"] == hasattr(mod, "parts") and callable(mod.build)


SCRIPT = """
from pathlib import Path

Path({mark!r}).write_text("imported")
TITLE = "side effect"
ORDER = 3
COST = 2.5


def parts(quick):
    return [("f", 1)]


def f(k):
    return k


def build(section):
    section.check("ran", 0.0, 1.0)


if __name__ == "__main__":
    raise SystemExit(0)
"""


def test_discovery_imports_no_script_and_the_section_still_runs(tmp_path):
    mark = tmp_path / "imported.txt"
    (tmp_path / "a.py").write_text(SCRIPT.format(mark=str(mark)))
    (a,) = discover_analyses(tmp_path)
    assert not mark.exists()  # read, not imported
    assert (a.title, a.order, a.cost) == ("side effect", 3.0, 2.5)
    assert isinstance(a.build, FromScript) and isinstance(a.parts, FromScript)
    assert a.parts(True) == [("f", 1)] and mark.exists()  # imported when called
    (s,) = run_analyses([a], log=io.StringIO())
    assert [c.passed for c in s.checks] == [True]


def test_metadata_that_only_the_import_can_tell(tmp_path):
    computed = SCRIPT.format(mark=str(tmp_path / "m.txt")).replace('TITLE = "side effect"', 'TITLE = "a" + "b"')
    imported_build = SCRIPT.format(mark=str(tmp_path / "m.txt")).replace("def build(section):", "def _build(section):")
    imported_build += "\nfrom math import sqrt as build\n"
    guarded = SCRIPT.format(mark=str(tmp_path / "m.txt")).replace(
        "COST = 2.5", "try:\n    COST = 2.5\nexcept Exception:\n    COST = 1"
    )
    for k, text in enumerate((computed, imported_build, guarded)):
        (tmp_path / f"s{k}.py").write_text(text)
        assert metadata.read(tmp_path / f"s{k}.py") is None
    # then discovery imports the script, as before: the computed title is the import's
    (a,) = discover_analyses(tmp_path, only=["s0"])
    assert a.title == "ab" and (tmp_path / "m.txt").exists()
