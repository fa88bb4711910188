"""Refusals around a study: before the work, with advice that fits the options given."""

from __future__ import annotations

import pytest

from stewart_drake.cli import main
from stewart_drake.commands import simulate as simulate_cmd
from stewart_drake.errors import StudyError
from stewart_drake.system.output_folder import MANIFEST, OutputFolder


def test_simulate_force_into_a_study_folder_is_refused_before_it_runs(tmp_path, capsys, monkeypatch):
    """``--force`` writes beside another command's files, never over them: a name that clashes is refused
    before the simulation, not after it."""
    out = tmp_path / "mc"
    with OutputFolder(out, command="montecarlo").writing() as tmp:
        (tmp / "summary.json").write_text('{"runs": 3}')

    def must_not_run(*a, **k):
        raise AssertionError("the simulation ran before the refusal")

    monkeypatch.setattr(simulate_cmd, "run_plan", must_not_run)
    rc = main(["simulate", "--duration", "0.02", "--out", str(out), "--force", "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1
    assert "'summary.json' exists, written by `montecarlo`" in err
    assert (out / "summary.json").read_text() == '{"runs": 3}'


def test_simulate_files_are_the_names_checked_before_the_run(tmp_path, capsys):
    """``simulate.FILES`` (checked before the work) is what simulate writes."""
    out = tmp_path / "sim"
    assert main(["simulate", "--duration", "0.02", "--engine", "python", "--out", str(out), "--no-progress"]) in (0, 1)
    capsys.readouterr()
    # every name but pil.csv, which only a --pil run writes
    assert {p.name for p in out.iterdir()} - {MANIFEST} == set(simulate_cmd.FILES) - {"pil.csv"}


def _far_csv(tmp_path):
    """A reference 2 m above utn-dynamic's base: beyond its stroke (0.55-0.95 m legs) whatever is drawn."""
    path = tmp_path / "far.csv"
    path.write_text("t,x,y,z,a,b,g\n" + "".join(f"{t},0,0,2.0,0,0,0\n" for t in (0, 0.1, 0.2)))
    return str(path)


@pytest.mark.parametrize("vary", [[], ["--vary", "anchor=±1mm"]])
def test_a_nominal_scenario_refused_gives_no_vary_advice(tmp_path, capsys, vary):
    """The nominal scenario itself is refused: the study's settings are at fault, with or without --vary, and
    neither a narrower --vary nor simulate's --allow-out-of-stroke (no option of a study) is offered."""
    csv = _far_csv(tmp_path)
    argv = ["montecarlo", "--trajectory", csv, *vary, "--runs", "2", "--workers", "0", "--duration", "0.2"]
    assert main([*argv, "--no-progress", "--out", str(tmp_path / "mc")]) == 2
    err = capsys.readouterr().err
    assert "nominal scenario (nothing drawn) is one simulate would refuse: the far reference leaves the stroke" in err
    assert "--vary" not in err and "--allow-out-of-stroke" not in err and err.count("\n") == 1
    assert not (tmp_path / "mc").exists()


def test_a_drawn_scenario_refused_still_advises_narrower_ranges(capsys, tmp_path):
    argv = ["montecarlo", "--vary", "anchor=±100mm", "--runs", "2", "--workers", "0", "--duration", "0.05"]
    assert main([*argv, "--no-progress", "--out", str(tmp_path / "mc")]) == 2
    err = capsys.readouterr().err
    assert (
        "run 0 (seed" in err
        and "leaves the stroke" in err
        and err.rstrip().endswith(StudyError.DRAW_ADVICE.format(vary_opt="--vary").strip())
    )
    assert "--allow-out-of-stroke" not in err


def test_simulate_force_over_a_users_file_is_refused_before_it_runs(tmp_path, capsys, monkeypatch):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "log.csv").write_text("my notes")

    def must_not_run(*a, **k):
        raise AssertionError("the simulation ran before the refusal")

    monkeypatch.setattr(simulate_cmd, "run_plan", must_not_run)
    assert main(["simulate", "--duration", "0.02", "--out", str(out), "--force", "--no-progress"]) == 2
    assert "'log.csv' exists and was not written by stewart-drake" in capsys.readouterr().err
    assert (out / "log.csv").read_text() == "my notes"
