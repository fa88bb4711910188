"""``stewart-drake response``: the verdict on the margins, and refusals of bad input."""

import json

from stewart_drake.cli import main


def test_designed_loop_passes_and_reports_margins(here, capsys):
    assert main(["response", "--platform", "utn-dynamic", "--controller", "float", "--out", "r"]) == 0
    out = json.loads(capsys.readouterr().out)
    # (the folder also holds its ownership mark, a dotfile)
    assert sorted(p.name for p in (here / "r").iterdir() if not p.name.startswith(".")) == [
        "response.json",
        "response.png",
    ]
    full = json.loads((here / "r" / "response.json").read_text())
    n = len(full["frequencies_hz"])
    assert n == 300 and len(full["setpoint"]["magnitude"]) == n and len(full["cartesian"]["phase_deg"][0]) == 6
    assert min(m["gain_margin_db"] for m in out["margins"]) >= out["min_gain_margin_db"]
    assert min(m["phase_margin_deg"] for m in out["margins"]) >= out["min_phase_margin_deg"]
    assert out["spectral_radius"] < 1 and out["failures"] == []


def test_doubled_gains_exit_1_naming_the_unstable_loop(capsys):
    # utn-dynamic's loop-at-a-time gain margin is ~6.4 dB (a factor ~2.1 on one leg); doubling every leg's gains
    # at once leaves the linearised loop unstable: the verdict must say so and exit 1
    assert (
        main(["response", "--platform", "utn-dynamic", "--controller", "float", "--set", "controller.gain_scale=2"])
        == 1
    )
    err = capsys.readouterr().err
    assert "unstable" in err


def test_measure_above_nyquist_is_refused(capsys):
    assert main(["response", "--controller", "float", "--measure", "600"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "stewart-drake response: error: measure: frequency 1 must be in (0, 500) Hz (below the Nyquist frequency), got 600.0"
    ]


def test_measuring_is_bounded_before_any_run(capsys):
    # 30 frequencies of 0.1 Hz: each run is two whole periods (20 s) after the settling, 600+ s in all
    argv = ["response", "--controller", "float"] + ["--measure", "0.1"] * 30
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "30 frequencies need" in err[0] and "more than 600 s" in err[0]
    assert main(["response", "--controller", "float"] + ["--measure", "10"] * 51) == 2
    assert "measure must be 1 … 50 frequencies, got 51" in capsys.readouterr().err


def test_pose_in_mm_and_degrees(capsys):
    # utn-dynamic's home is (0, 0, 0.7 m, 0, 0, 0): given explicitly in the CLI's units it is the default's loop
    assert main(["response", "--controller", "float", "--pose", "0", "0", "700", "0", "0", "0"]) == 0
    given = json.loads(capsys.readouterr().out)
    assert main(["response", "--controller", "float"]) == 0
    default = json.loads(capsys.readouterr().out)
    assert given["pose"] == default["pose"] and given["margins"] == default["margins"]
    # a tilted pose (2° about x) is a different loop
    assert main(["response", "--controller", "float", "--pose", "0", "0", "700", "2", "0", "0"]) in (0, 1)
    tilted = json.loads(capsys.readouterr().out)
    assert abs(tilted["pose"][3] - 0.0349066) < 1e-6 and tilted["margins"] != default["margins"]


def test_plant_step_must_divide_the_period(capsys):
    assert main(["response", "--controller", "float", "--set", "run.plant_step=0.3ms"]) == 2
    err = capsys.readouterr().err
    assert "run.plant_step 0.0003 s must divide controller.period 0.001 s" in err
