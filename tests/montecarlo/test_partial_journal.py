"""``montecarlo``'s resume journal (``montecarlo.partial.jsonl``, a ``system.journal``): a hand-edited row is refused
naming the file and line, and a row whose chain was rewritten is still checked against the study's draws."""

from __future__ import annotations

import json
import re

from stewart_drake.cli import main
from stewart_drake.montecarlo import study as study_mod
from stewart_drake.system.journal import JournalWriter, header_line

VARY = ["gain_scale=0.9..1.1", "plate_mass=±20%"]


def _interrupted(tmp_path, monkeypatch):
    """A study of 3 runs interrupted after 2: its folder holds the journal of runs 0 and 1."""
    real = study_mod.run_row

    def interrupted(study, i):
        if i == 2:
            raise KeyboardInterrupt
        return real(study, i)

    out = tmp_path / "mc"
    monkeypatch.setattr(study_mod, "run_row", interrupted)
    args = ["montecarlo", "--runs", "3", "--seed", "5", "--vary", *VARY, "--out", str(out), "--workers", "0"]
    args += ["--duration", "0.15", "--no-progress"]
    assert main(args) == 130
    monkeypatch.setattr(study_mod, "run_row", real)
    return out, args


def test_an_edited_or_out_of_range_row_is_refused_and_nothing_lands_in_the_results(tmp_path, monkeypatch, capsys):
    """An edited row (gain_scale 5.0, outside 0.9..1.1) landed in results.csv with exit 0."""
    out, args = _interrupted(tmp_path, monkeypatch)
    path = out / study_mod.PARTIAL
    lines = path.read_text().splitlines()
    rows = [json.loads(line)["row"] for line in lines[1:]]
    assert len(rows) == 2 and 0.9 <= rows[1]["gain_scale"] <= 1.1
    capsys.readouterr()
    # by hand: the line no longer verifies
    lines[2] = lines[2].replace(f'"gain_scale": {rows[1]["gain_scale"]!r}', '"gain_scale": 5.0')
    path.write_text("\n".join(lines) + "\n")
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert re.fullmatch(rf"stewart-drake montecarlo: error: {re.escape(str(path))}:3: does not verify .*", err), err
    # the chain rewritten (its key is not secret): the draw is checked against the study's seed
    drawn = rows[1]["gain_scale"]
    rows[1]["gain_scale"] = 5.0
    path.write_text(header_line(json.loads(lines[0])["key"]) + "\n")
    w = JournalWriter(path, json.loads(lines[0])["key"])
    w.append_texts([json.dumps(r) for r in rows])
    w.close()
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"stewart-drake montecarlo: error: {path}:3: run 1: gain_scale = 5.0 is not the study's draw for that run "
        f"({drawn!r}); nothing was resumed from it: remove the file to start again, or give another folder"
    )
    assert not (out / "results.csv").exists() and not (out / "results.parquet").exists()
