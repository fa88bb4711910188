"""``scripts/compare_behaviour.py`` on two small recordings: the feed-forward words' boundary ticks are counted and
listed and are not a difference; a key a later tree adds (``ADDED_KEYS``) is listed, not a difference; any other
change is."""

import importlib.util
import json
from pathlib import Path

import pytest

SCRIPT = Path(__file__).parents[2] / "scripts" / "compare_behaviour.py"


@pytest.fixture(scope="module")
def compare():
    spec = importlib.util.spec_from_file_location("compare_behaviour", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _recording(folder: Path, summary: dict, words: list, engine: str) -> Path:
    folder.mkdir()
    call = {"name": "simulate", "exit_code": 0, "files": {"sim/summary.json": summary}}
    (folder / "01-simulate.json").write_text(json.dumps(call))
    cases = {"case": {"engine": engine, "words": words}}
    (folder / "feedforward-words.json").write_text(json.dumps({"name": "feedforward-words", "cases": cases}))
    return folder


def test_boundary_ticks_are_listed_and_an_added_key_is_not_a_difference(compare, tmp_path, capsys):
    a = _recording(tmp_path / "a", {"chatter": False}, [[1, 2, 3, 4, 5, 6], [7, 8, 9, 10, 11, 12]], "numpy")
    b = _recording(
        tmp_path / "b", {"chatter": False, "feedforward_engine": "c"}, [[1, 2, 3, 4, 5, 6], [7, 8, 9, 10, 12, 12]], "c"
    )
    assert compare.main([str(a), str(b)]) == 0
    out = capsys.readouterr().out
    assert "feedforward-words: 1 boundary tick in 2 ticks (engines A numpy, B c)" in out
    assert "case tick 1 leg 5: 11  !=  12" in out
    assert "added in" in out and "feedforward_engine" in out
    assert "2/2 identical" in out


def test_a_changed_verdict_or_a_missing_case_is_a_difference(compare, tmp_path, capsys):
    a = _recording(tmp_path / "a", {"chatter": False}, [[1, 2, 3, 4, 5, 6]], "numpy")
    b = _recording(tmp_path / "b", {"chatter": True}, [[1, 2, 3, 4, 5, 6], [1, 2, 3, 4, 5, 6]], "c")
    assert compare.main([str(a), str(b)]) == 1
    out = capsys.readouterr().out
    assert "01-simulate: differs" in out and "not comparable: case" in out
