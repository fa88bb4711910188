"""The Monte Carlo study: SPEC parsing, per-run draws, the drawn sensor, resume, Dask rows, replay."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.montecarlo import study as study_mod
from stewart_drake.montecarlo.scenario import Study, draw, run_scenario, run_seed
from stewart_drake.montecarlo.spec import SpecError, parse_spec
from stewart_drake.montecarlo.summary import read_table, sensitivity

VARY = ["anchor=±0.5mm", "sensor_resolution=10um", "latency_jitter=200us", "plate_mass=±20%"]
# Short runs: 0.15 s of the seed trajectory (150 controller ticks).
SHORT = ["--duration", "0.15", "--no-progress"]


@pytest.fixture(scope="module")
def platform():
    return load_platform("utn-dynamic")


def test_spec_values_units_and_laws():
    s = parse_spec(
        "anchor=±0.5mm sensor_resolution=10um latency=sample|none actuator_lag=1ms..3ms plate_mass=±20% force_limit=150|200"
    )
    assert s.laws["anchor"].kind == "plusminus" and s.laws["anchor"].values == (0.0005,)
    assert s.laws["sensor_resolution"].values == (1e-05,)  # decimal scaling: exactly the float 1e-05
    assert s.laws["latency"].values == ("sample", "none")
    assert s.laws["actuator_lag"].values == (0.001, 0.003)
    assert s.laws["plate_mass"].kind == "relative" and s.laws["plate_mass"].values == (0.2,)
    assert s.laws["force_limit"].values == (150.0, 200.0)


def test_spec_yaml_names_the_line(tmp_path):
    f = tmp_path / "vary.yaml"
    f.write_text("anchor: ±0.5mm\nplate_mas: ±20%\n")
    with pytest.raises(SpecError, match=r"vary.yaml:2: unknown key 'plate_mas' \(did you mean 'plate_mass'\?\)"):
        parse_spec([str(f)])
    f.write_text("anchor: ±0.5mm\nsensor_noise: 2um\n")
    assert parse_spec([str(f)]).laws["sensor_noise"].values == (2e-06,)


@pytest.mark.parametrize(
    "word, message",
    [
        ("ancor=±1mm", "did you mean 'anchor'"),
        ("anchor=±1furlong", "cannot read '1furlong'"),
        ("anchor=±5%", "percentage of a zero nominal"),
        ("actuator_lag=3ms..1ms", "low end is above its high end"),
        ("latency=sometimes", "'sometimes' is not one of"),
    ],
)
def test_bad_spec_is_one_line_exit_2(capsys, tmp_path, word, message):
    assert main(["montecarlo", "--vary", word, "--runs", "1", "--out", str(tmp_path / "o"), *SHORT]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_runs_times_duration_bounded_before_running(capsys, tmp_path):
    assert main(["montecarlo", "--runs", "100000", "--duration", "10", "--out", str(tmp_path / "o")]) == 2
    assert "simulated s is more than the bound" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("argv", "what"),
    [
        (["--runs", "1", "--duration", "0.05", "--plant-step", "1e-9"], "per run is 5e+07 plant steps"),
        (["--runs", "1001", "--duration", "5", "--plant-step", "1e-5"], "--runs 1001 × 5e+05 plant steps = 5.005e+08"),
    ],
)
def test_plant_steps_bounded_before_running(capsys, tmp_path, argv, what):
    """The work and each run's log grow with plant steps, not simulated seconds: --plant-step 1e-9 (5e7
    steps of 0.05 s) ran on, its log headed for ~200 GB. Bounded like the default 1 ms step's seconds:
    600 s per run (6e5 steps) and 500,000 s in all (5e8 steps)."""
    assert main(["montecarlo", *argv, "--workers", "0", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert what in err and "more than the bound" in err and err.count("\n") == 1
    assert not (tmp_path / "o").exists()


def test_each_run_redraws_alone(platform):
    """Run i's draw depends on (S, i) only: drawn alone equals drawn in a sequence, and it is within the
    SPEC's bounds; other indices and seeds draw differently."""
    st = Study(platform, parse_spec(VARY), seed=11, runs=5)
    draws = [draw(st, i) for i in range(5)]
    seed3, d3 = draw(Study(platform, parse_spec(VARY), seed=11, runs=1), 3)
    assert seed3 == draws[3][0] == run_seed(11, 3)
    assert (
        np.array_equal(d3.base_anchor_offset, draws[3][1].base_anchor_offset)
        and d3.plate_mass == draws[3][1].plate_mass
    )
    assert len({s for s, _ in draws}) == 5 and run_seed(12, 3) != seed3
    for _, d in draws:
        assert np.abs(d.base_anchor_offset).max() <= 0.5e-3 and np.abs(d.top_anchor_offset).max() <= 0.5e-3
        assert 0.8 * platform.mass <= d.plate_mass <= 1.2 * platform.mass
        assert np.all(d.leg_offset == 0) and d.gain_scale == 1.0


def test_sensor_offset_moves_the_legs_by_its_value(platform):
    """A +1 mm sensor zero makes the loop hold each true length 1 mm short of the set-point (the
    controller servoes the reading L + 1 mm): the leg error is −1 mm up to the float twin's own tracking
    error on this trajectory (< 0.07 mm, bench_integrators)."""
    st = Study(platform, parse_spec(["leg_offset=1mm"]), seed=0, runs=1, controller="float", duration=0.4)
    row = run_scenario(st, 0, keep_log=True)
    log = row["log"]
    e = log.length_error(st.reference(), platform)
    late = log.t > 0.2
    assert np.abs(e[late] + 1e-3).max() < 0.1e-3


def test_sensitivity_finds_the_parameter_that_drives_the_error():
    """A synthetic table where the error is a monotone function of one parameter and independent of
    another: ρ = 1 for the first, ranked first."""
    rng = np.random.default_rng(0)
    x, z = rng.uniform(size=50), rng.uniform(size=50)
    rows = [
        {
            "run": i,
            "seed": i,
            "a": float(x[i]),
            "b": float(z[i]),
            "max_leg_error_m": float(x[i] ** 3),
            "error": "",
            "lost_tracking": False,
        }
        for i in range(50)
    ]
    ranking = sensitivity(rows)
    assert ranking[0]["parameter"] == "a" and ranking[0]["spearman"] == pytest.approx(1.0)
    assert abs(ranking[1]["spearman"]) < 0.4


def _study_args(out, runs, *extra):
    return ["montecarlo", "--runs", str(runs), "--seed", "5", "--vary", *VARY, "--out", str(out), *SHORT, *extra]


def test_study_resumes_without_repeating_finished_runs(tmp_path, monkeypatch, capsys):
    """Interrupted after run 1: started again, it runs only the missing ones, and the table equals an
    uninterrupted study's (wall time excluded)."""
    full = tmp_path / "full"
    assert main(_study_args(full, 3, "--workers", "0")) == 0
    calls = []
    real = study_mod.run_row

    def interrupted(study, i):
        if i == 2:
            raise KeyboardInterrupt
        calls.append(i)
        return real(study, i)

    part = tmp_path / "part"
    monkeypatch.setattr(study_mod, "run_row", interrupted)
    assert main(_study_args(part, 3, "--workers", "0")) == 130
    assert calls == [0, 1] and (part / study_mod.PARTIAL).exists()

    def counting(study, i):
        calls.append(i)
        return real(study, i)

    monkeypatch.setattr(study_mod, "run_row", counting)
    assert main(_study_args(part, 3, "--workers", "0")) == 0
    assert calls == [0, 1, 2]
    a, b = read_table(full), read_table(part)
    assert [{k: v for k, v in r.items() if k != "wall_s"} for r in a] == [
        {k: v for k, v in r.items() if k != "wall_s"} for r in b
    ]
    assert not (part / study_mod.PARTIAL).exists()
    summary = json.loads((part / "summary.json").read_text())
    assert summary["runs"] == 3 and set(summary["metrics"]["max_leg_error_m"]) >= {"p50", "p95", "max"}
    # another study's settings in the same folder: refused, folder untouched
    assert (
        main(
            ["montecarlo", "--runs", "3", "--seed", "6", "--vary", *VARY, "--out", str(part), *SHORT, "--workers", "0"]
        )
        == 2
    )
    assert "holds another study" in capsys.readouterr().err


def test_refuses_a_folder_it_did_not_write(tmp_path, capsys):
    (tmp_path / "mine.txt").write_text("keep")
    assert main(_study_args(tmp_path, 1, "--workers", "0")) == 2
    assert "not written by stewart-drake" in capsys.readouterr().err and (tmp_path / "mine.txt").read_text() == "keep"


def test_rows_same_with_one_or_two_dask_workers(tmp_path):
    """``--workers 1`` (the study's own LocalCluster) and ``--scheduler`` of a running 2-worker cluster:
    the same rows, wall time excluded."""
    from distributed import LocalCluster

    assert main(_study_args(tmp_path / "w1", 3, "--workers", "1")) == 0
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        assert main(_study_args(tmp_path / "w2", 3, "--scheduler", cluster.scheduler_address)) == 0
    tables = [[{c: v for c, v in r.items() if c != "wall_s"} for r in read_table(tmp_path / w)] for w in ("w1", "w2")]
    assert tables[0] == tables[1]
    assert len({r["max_leg_error_m"] for r in tables[0]}) == 3  # the runs do differ


def test_replay_is_bit_identical_and_the_check_can_fail(tmp_path, capsys):
    """--replay K re-runs run K alone: every column bit-identical to the study's row. A row altered by
    one ulp is caught (exit 1, the column named)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = tmp_path / "s"
    assert main(_study_args(out, 2, "--workers", "0")) == 0
    capsys.readouterr()
    assert main(["montecarlo", "--replay", "1", "--out", str(out), "--no-animation", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["bit_identical"] and result["differing_columns"] == []
    log = np.load(out / "replay-1" / "log.npz")
    assert log["t"][-1] == pytest.approx(0.15)
    rows = read_table(out)
    rows[1]["max_leg_error_m"] = float(np.nextafter(rows[1]["max_leg_error_m"], 1.0))
    pq.write_table(pa.Table.from_pylist(rows), out / "results.parquet")
    assert main(["montecarlo", "--replay", "1", "--out", str(out), "--no-animation", "--json"]) == 1
    assert json.loads(capsys.readouterr().out)["differing_columns"] == ["max_leg_error_m"]


def test_unreachable_program_refused_before_any_run(tmp_path, capsys):
    """examples/circle.stw is written for utn-kinematic: on utn-dynamic its moves leave the stroke, and the
    study stops before running anything (the program's diagnostics, exit 2, no folder)."""
    from pathlib import Path

    program = Path(__file__).resolve().parents[2] / "examples" / "circle.stw"
    assert (
        main(
            [
                "montecarlo",
                "--program",
                str(program),
                "--runs",
                "2",
                "--out",
                str(tmp_path / "o"),
                *SHORT,
                "--workers",
                "0",
            ]
        )
        == 2
    )
    assert "out of reach on platform utn-dynamic" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_a_pickled_run_scenario_builds_the_same_diagram(platform):
    """Workers build their Diagram from a pickled ``Scenario``: run 1 of a study (perturbed plant, drawn
    sensor noise and jitter, scaled gains) simulated from its unpickled scenario gives the same logs, bit
    for bit, as from the original object."""
    import pickle

    from stewart_drake.drake.simulation import build_simulation
    from stewart_drake.montecarlo.scenario import scenario

    study = Study(
        machine=platform,
        spec=parse_spec(VARY + ["sensor_noise=5um", "gain_scale=±10%"]),
        seed=11,
        runs=2,
        duration=0.05,
    )
    _, d, sc = scenario(study, 1)
    back = pickle.loads(pickle.dumps(sc))
    assert back.plant_platform.mass == sc.plant_platform.mass != platform.mass  # the draw reaches the plant
    assert np.abs(back.sensor.noise).max() > 0 and back.sensor.jitter.max() > 0  # ... and the sensor
    a, b = (build_simulation(s).run(0.05) for s in (sc, back))
    for k in a.ARRAYS:
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))


def test_a_study_stored_without_an_integrator_replays_under_cenic(platform):
    """Studies written while error-controlled CENIC was the default stored ``integrator: null``; they are
    read back as ``cenic`` (what they ran under), never as today's default. New studies store the
    integrator by name, so a change of default cannot mix integrators within one study."""
    st = Study(platform, parse_spec(["anchor=±0.5mm"]), seed=1, runs=2, duration=0.1)
    settings = study_mod.study_settings(st)
    assert settings["integrator"] == "cenic-fixed"
    old = study_mod.study_from_settings({**settings, "integrator": None}, runs=2)
    assert old.integrator == "cenic" and study_mod.study_from_settings(settings, 2).integrator == "cenic-fixed"


def test_replay_runs_the_stored_study_and_refuses_other_options(tmp_path, capsys, monkeypatch):
    """--replay runs the study stored in --out. Study options that describe another study (a SAP study
    replayed with --integrator cenic) were silently ignored: they are refused in one line naming the
    difference. A study run with the C engine replays without a compiler (the Python engine, with the
    note: bit-identical). A study.json or results.parquet a study did not write is one line naming it
    (it was a KeyError traceback)."""
    from stewart_drake.errors import OptionError
    from stewart_drake.system.c_build import CC_ENV

    out = tmp_path / "s"
    options = ["--runs", "1", "--duration", "0.05", "--integrator", "sap", "--engine", "c"]
    assert main(["montecarlo", *options, "--workers", "0", "--out", str(out), "--no-progress"]) == 0
    replay = ["montecarlo", "--replay", "0", "--out", str(out), "--no-animation", "--json"]
    capsys.readouterr()
    assert main([*replay, *options]) == 0  # the study's own options: the same study
    assert json.loads(capsys.readouterr().out)["bit_identical"]

    assert main([*replay, "--duration", "0.05", "--integrator", "cenic"]) == 2
    err = capsys.readouterr().err.strip()
    diff = "integrator 'sap' there, 'cenic' here"
    assert err == "stewart-drake montecarlo: error: " + OptionError.REPLAY_OTHER.format(run=0, out=str(out), diff=diff)

    monkeypatch.setenv(CC_ENV, str(tmp_path / "no-cc"))  # no compiler
    assert main(replay) == 0
    io = capsys.readouterr()
    assert json.loads(io.out)["bit_identical"] and "running the Python engine instead" in io.err
    monkeypatch.delenv(CC_ENV)

    assert main(["montecarlo", "--no-animation", *options, "--workers", "0", "--out", str(out)]) == 2
    assert capsys.readouterr().err.strip().endswith("--no-animation only applies with --replay")

    stored = json.loads((out / "study.json").read_text())
    del stored["settings"]["integrator"]
    (out / "study.json").write_text(json.dumps(stored))
    assert main(replay) == 2
    reason = OptionError.BAD_STUDY.format(path=out / "study.json", reason="no 'integrator'")
    assert capsys.readouterr().err.strip() == f"stewart-drake montecarlo: error: {reason}"
    (out / "study.json").write_text("{")
    assert main(replay) == 2
    assert capsys.readouterr().err.strip().startswith(f"stewart-drake montecarlo: error: --replay: {out}/study.json is")


def test_the_parent_compiles_the_firmware_the_workers_load(platform, tmp_path, monkeypatch):
    """``study.compile_firmware`` (called before the workers start) leaves run 0's compiled firmware in the
    C build cache: a run then builds its C engine without calling the compiler at all."""
    from stewart_drake.system import c_build

    if not c_build.compilers():
        pytest.skip("no C compiler")
    monkeypatch.setenv("STEWART_DRAKE_CACHE", str(tmp_path / "cache"))
    study = Study(machine=platform, spec=parse_spec(VARY), seed=3, runs=2, duration=0.02, engine="c")
    study_mod.compile_firmware(study, 0)
    assert len(list((tmp_path / "cache").glob("sd-*.so"))) >= 1

    def no_compiler(*args, **kwargs):
        raise AssertionError(f"compiled again: {args[0]}")

    monkeypatch.setattr(c_build.subprocess, "run", no_compiler)
    row = run_scenario(study, 1)  # another draw of the same study: the same firmware
    assert row["error"] == "" and np.isfinite(row["max_leg_error_m"])
