"""A Monte Carlo study is a machine, a motion and what it varies (issue 36, items 2-3): the machine file's firmware
format, payload and run settings reach every run; a ``--vary`` key is one row of ``spec.KEYS`` naming the spec path
it draws; errors name spec paths in the API and flags on the command line."""

import pickle
from pathlib import Path

import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.errors import MachineError, SpecError, StudyError
from stewart_drake.montecarlo import spec as spec_mod
from stewart_drake.montecarlo.api import make_study
from stewart_drake.montecarlo.scenario import Study, draw, scenario
from stewart_drake.montecarlo.spec import VaryKey, parse_spec
from stewart_drake.montecarlo.study import check_study, study_key

NEWCOMER = Path(__file__).parents[2] / "examples" / "newcomer-210kg.yaml"


def test_a_study_of_the_newcomer_machine_runs_its_own_firmware_format(tmp_path):
    """The newcomer's machine file asks for a 30 µm IK length LSB (with the DSP's 1 mm its loop chatters: one
    LSB step is ~5.7 kN through kv/T) and carries a 150 kg payload. Each run's controller computes in that format
    with gains designed for the loaded plate, and the study passes (no chatter, no lost tracking)."""
    machine = sd.load_machine(NEWCOMER)
    r = sd.montecarlo(
        NEWCOMER, out=tmp_path / "mc", runs=2, seed=0, vary=["anchor=±0.1mm"], workers=0,
        **{"run.duration": 0.5, "controller.engine": "python"},
    )  # fmt: skip
    assert r.ok, r.summary["failed_runs"]
    assert r.summary["settings"]["machine"]["firmware.length_lsb"] == 30e-6
    assert r.summary["settings"]["machine"]["payload.mass"] == 150.0 and r.summary["settings"]["fit"] is True
    study = make_study(NEWCOMER, None, ["anchor=±0.1mm"], 2, 0, {"run.duration": 0.5})
    # what a Dask worker receives: the study pickled, the machine with it (the same settings, the same draws)
    copy = pickle.loads(pickle.dumps(study))
    assert study_key(copy) == study_key(study) and copy.machine.firmware == machine.firmware
    assert draw(copy, 1)[1].columns() == draw(study, 1)[1].columns()
    for i in range(2):
        sc = scenario(study, i)[2]
        fmt = sc.config.ik_format
        assert (fmt.word_bits, fmt.length_lsb, fmt.trig) == (16, 30e-6, "tfr16")
        # the controller's model carries the payload: its plate is the 60 kg plate plus the 150 kg point mass
        assert sc.platform.mass == machine.loaded_platform.mass == 210.0
        assert sc.plant_platform.mass == 210.0  # anchor tolerances move joints, not masses
        assert sc.trajectory.name == "rotating"  # the machine's first motion (fitted: run.fit)


def test_a_new_vary_key_is_one_table_row_drawn_checked_and_run(monkeypatch):
    """Adding ``length_lsb`` -> ``firmware.length_lsb`` to ``KEYS`` (and nothing else) makes it a ``--vary`` key:
    its draws are row columns, each reaches its run's fixed-point IK, and a draw the machine would refuse
    (a negative LSB) stops the study naming the run and the spec path's rule."""
    monkeypatch.setitem(spec_mod.KEYS, "length_lsb", VaryKey("length", 0, False, "firmware.length_lsb"))
    p = sd.load_platform("utn-dynamic")
    study = Study(p, parse_spec(["length_lsb=30um|40um"]), seed=4, runs=6, duration=0.05)
    drawn = [draw(study, i)[1] for i in range(study.runs)]
    lsbs = [d.columns()["length_lsb_m"] for d in drawn]
    assert set(lsbs) == {30e-6, 40e-6}  # both choices drawn over 6 runs at this seed (16-bit words hold the stroke)
    for i, d in enumerate(drawn):
        assert scenario(study, i)[2].config.ik_format.length_lsb == d.length_lsb
    check_study(study)  # 10 µm sensor counts divide both LSBs: every draw passes
    bad = Study(p, parse_spec(["length_lsb=-1mm"]), seed=4, runs=1, duration=0.05)
    with pytest.raises(StudyError, match=r"^run 0 .*length_lsb_m=-0\.001\): firmware\.length_lsb must be > 0 m"):
        check_study(bad)


def test_the_api_names_spec_paths_and_the_command_line_names_flags(tmp_path, capsys):
    """The same bad period: ``sd.montecarlo`` names the spec path (no flag in an API message); the command
    line's ``--set`` names the path and ``--duration`` the flag; nothing runs, exit 2."""
    with pytest.raises(MachineError, match=r"^controller\.period must be > 0 s, got -1") as e:
        sd.montecarlo("utn-dynamic", out=tmp_path / "a", runs=1, **{"controller.period": -1})
    assert "--" not in str(e.value)
    with pytest.raises(MachineError, match=r"^run\.duration must be > 0 s, got -0\.5"):
        sd.montecarlo("utn-dynamic", out=tmp_path / "a", runs=1, duration=-0.5)
    with pytest.raises(StudyError, match=r"^runs must be 1 … 100000, got 0$"):
        sd.montecarlo("utn-dynamic", out=tmp_path / "a", runs=0)
    with pytest.raises(SpecError, match=r"^vary: unknown key 'wobble'"):
        sd.montecarlo("utn-dynamic", out=tmp_path / "a", vary=["wobble=3"])
    refused = (
        r"^run 0 .*: vary sample_period must be a positive number of seconds, got -0\.001; .*narrow the vary ranges$"
    )
    with pytest.raises(StudyError, match=refused):
        sd.montecarlo("utn-dynamic", out=tmp_path / "a", runs=1, vary=["sample_period=-1ms"], duration=0.05)
    common = ["montecarlo", "--machine", str(NEWCOMER), "--runs", "1", "--workers", "0", "--out", str(tmp_path / "b")]
    assert main([*common, "--set", "controller.period=-1ms"]) == 2
    assert "controller.period must be > 0 s, got -1ms" in capsys.readouterr().err
    assert main([*common, "--duration", "-0.5"]) == 2
    assert "--duration must be > 0 s, got -0.5" in capsys.readouterr().err
    assert main([*common, "--runs", "0"]) == 2
    assert "--runs must be 1 … 100000, got 0" in capsys.readouterr().err
    assert main([*common, "--platform", "utn-dynamic"]) == 2
    assert "--machine" in capsys.readouterr().err
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_a_percentage_is_of_the_machines_own_value():
    """``payload=±10%`` draws about the machine's payload (the newcomer's 150 kg: within 135 … 165 kg, the
    controller's model keeping 150 kg); on a machine without a payload it is a percentage of zero: refused."""
    newcomer = Study(sd.load_machine(NEWCOMER), parse_spec(["payload=±10%"], "vary"), seed=0, runs=8)
    masses = [draw(newcomer, i)[1].payload for i in range(newcomer.runs)]
    assert all(135.0 <= m <= 165.0 for m in masses) and len(set(masses)) == len(masses)
    assert draw(newcomer, 0)[1].machine().payload.mass == masses[0] and newcomer.machine.payload.mass == 150.0
    bare = Study(sd.load_platform("utn-dynamic"), parse_spec(["payload=±10%"], "vary"), seed=0, runs=1)
    with pytest.raises(SpecError, match=r"^vary: payload: '±10%': a percentage of a zero nominal"):
        check_study(bare)


def test_a_study_of_a_screw_machine_runs_its_screws():
    # the drawn machine's screws reach each run (the lag's draws, actuator_lag and force_limit, are the lag's)
    study = make_study(NEWCOMER, None, ["anchor=±0.1mm"], 1, 0, {"run.duration": 0.2, "actuators.model": "screw"})
    sc = scenario(study, 0)[2]
    assert sc.actuators.model == "screw" and sc.actuators.screw == study.machine.actuators.screw(4000.0)
