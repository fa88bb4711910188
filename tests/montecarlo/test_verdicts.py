"""Every Monte Carlo run is judged as ``simulate`` judges a run (``control.verdict.run_verdict``): chatter,
saturation and tracking are columns of the rows, a failing run is listed with its reason and fails the study."""

from __future__ import annotations

import json
from pathlib import Path

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.montecarlo.summary import FAILURE_SEPARATOR, VERDICT_COLUMNS, read_table

# The 150 kg platform whose fixed-point loop chatters with the default 1 mm IK LSB (simulate exits 1); 0.3 s of
# its fitted seed motion (300 ticks) shows the chatter (a ripple ~10 % of the command range, bound 5 %).
NEWCOMER = str(Path(__file__).parents[2] / "examples" / "newcomer-150kg.yaml")
SHORT = ["--fit", "--duration", "0.3", "--engine", "python", "--no-progress"]


def test_a_chattering_study_fails_with_each_run_and_its_reason(tmp_path, capsys):
    out = tmp_path / "mc"
    # one Dask worker (the default): the rows, verdicts included, come back from the worker process
    rc = main(["montecarlo", "--platform", NEWCOMER, "--runs", "2", "--workers", "1", "--out", str(out), *SHORT])
    err = capsys.readouterr().err
    assert rc == 1
    assert "2 of 2 runs failed" in err and "run 0: chatter: force ripple" in err and "run 1: chatter:" in err
    rows = read_table(out)
    assert all(set(VERDICT_COLUMNS) <= set(r) for r in rows)
    assert all(r["chatter"] and r["failures"].startswith("chatter:") for r in rows)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["ok"] is False
    assert [f["run"] for f in summary["failed_runs"]] == [0, 1]
    assert all(f["reason"].startswith("chatter:") for f in summary["failed_runs"])
    # the CSV carries the same columns (a user's spreadsheet sees the verdicts)
    header = (out / "results.csv").read_text().splitlines()[0].split(",")
    assert {"force_ripple_rms_N", "chatter", "saturated", "tracking_failed", "failures"} <= set(header)

    # the same run as simulate gives the same ripple and the same failure (nothing varied: every run is the
    # nominal platform, so its loop is simulate's, bit for bit)
    sim = sd.simulate(sd.load_platform(NEWCOMER), "seed", controller="fixed", duration=0.3, fit=True, engine="python")
    assert not sim.ok
    assert rows[0]["force_ripple_rms_N"] == max(sim.summary["force_ripple_N"])
    assert rows[0]["failures"].split(FAILURE_SEPARATOR) == sim.verdict["failures"]


def test_the_api_study_is_not_ok_when_a_run_chatters(tmp_path):
    r = sd.montecarlo(
        sd.load_platform(NEWCOMER), out=tmp_path / "mc", runs=2, fit=True, duration=0.3, engine="python", workers=0
    )
    assert r.ok is False and not r.lost_tracking_runs  # the errors stay small: only the force shows the fault
    assert r.summary["failed_runs"][0]["run"] == 0 and "chatter" in r.summary["failed_runs"][0]["reason"]
    assert list(r.to_pandas()["chatter"]) == [True, True]


def test_a_study_that_does_not_chatter_passes(tmp_path, capsys):
    """utn-dynamic's fixed-point loop: a ripple of ~1.3 % of its command range (bound 5 %), tracked within
    a few mm: every verdict passes, the study exits 0."""
    out = tmp_path / "mc"
    argv = ["montecarlo", "--runs", "2", "--vary", "anchor=±0.5mm", "--workers", "0", "--out", str(out)]
    assert main([*argv, "--duration", "0.3", "--engine", "python", "--no-progress", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["ok"] is True and summary["failed_runs"] == []
    rows = read_table(out)
    assert all(not r["chatter"] and not r["saturated"] and not r["tracking_failed"] for r in rows)
    assert all(r["failures"] == "" and r["force_ripple_rms_N"] > 0 for r in rows)


def test_a_resumed_row_without_verdicts_is_run_again(tmp_path, monkeypatch):
    """A journal row written before runs were judged would pass unjudged into the results: it is re-run."""
    from stewart_drake.montecarlo import study as study_mod
    from stewart_drake.montecarlo.scenario import Study
    from stewart_drake.montecarlo.spec import parse_spec

    st = Study(sd.load_platform("utn-dynamic"), parse_spec(["anchor=±0.5mm"]), seed=1, runs=2, duration=0.02)
    judged = study_mod.run_study(st, None, workers=0, progress=False)
    out = tmp_path / "mc"
    w = study_mod.PartialWriter(out, study_mod.study_key(st))
    for r in judged:
        w.write({k: v for k, v in r.items() if k not in VERDICT_COLUMNS} if r["run"] == 0 else r)
    w.close()
    calls = []
    real = study_mod.run_row
    monkeypatch.setattr(study_mod, "run_row", lambda study, i: calls.append(i) or real(study, i))
    rows = study_mod.run_study(st, out, workers=0, progress=False)
    assert calls == [0]  # run 1 kept its judged row
    assert [r["failures"] for r in rows] == [r["failures"] for r in judged]
    assert [r["force_ripple_rms_N"] for r in rows] == [r["force_ripple_rms_N"] for r in judged]
