"""A run's and a firmware's options are declared once: the firmware format keywords (``**format``) are checked
in one place as the machine's fields are, and the API's messages name spec paths and keywords, never a
command-line flag (the commands turn them into flags at their edge)."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

import stewart_drake as sd
from stewart_drake.api.firmware import FORMAT_PATHS
from stewart_drake.api.simulation import plan_run
from stewart_drake.cli import main
from stewart_drake.errors import MachineError, StewartError, UsageError

FIRMWARE_FUNCTIONS = ("generate", "check", "certify", "certify_tick", "optimize")


@pytest.mark.parametrize("name", FIRMWARE_FUNCTIONS)
def test_firmware_functions_take_the_format_as_one_keyword_set(name):
    """Each function's own keywords hold none of the format's: the format is ``**format``, checked once."""
    params = inspect.signature(getattr(sd.firmware, name)).parameters
    assert not set(FORMAT_PATHS) & set(params)
    assert params["format"].kind is inspect.Parameter.VAR_KEYWORD


def test_an_unknown_format_keyword_is_named_with_the_valid_ones(tmp_path):
    with pytest.raises(
        MachineError, match=r"^unknown firmware format keyword 'word_bit'; the keywords are word_bits, "
    ):
        sd.firmware.generate(sd.load_platform("utn-dynamic"), tmp_path / "fw", compile=False, word_bit=12)
    assert not (tmp_path / "fw").exists()  # refused before any output


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        (dict(length_lsb=-1), r"^firmware\.length_lsb must be > 0 m, got -1$"),
        (dict(word_bits=24, trig="exact"), r"^firmware\.word_bits must be in 8\.\.16 for generated C .*, got 24$"),
        (dict(word_bits=12), r"^firmware\.word_bits must be 16 with trig tfr16 \(use trig exact\), got 12$"),
        (dict(rate=-5), r"^rate must be a positive number of Hz up to 1e6, got -5$"),
        (dict(sensor_resolution=0), r"^sensors\.resolution must be > 0 m, got 0$"),
        (dict(convention="xyz"), r"^firmware\.convention: 'xyz' is not one of utn, zyx$"),
    ],
)
@pytest.mark.parametrize("name", ["certify", "certify_tick"])
def test_format_errors_name_spec_paths_not_flags(name, keywords, message):
    with pytest.raises(StewartError, match=message) as e:
        getattr(sd.firmware, name)("utn-dynamic", **keywords)
    assert "--" not in str(e.value)


def test_a_format_keyword_reaches_the_certificate():
    """``length_lsb`` given replaces the machine's 1 mm: the certificate's format is the one given."""
    r = sd.firmware.certify("utn-dynamic", box=["pz=150..160"], max_cells=50, length_lsb=5e-4)
    assert r.certificate.fmt.length_lsb == 5e-4 and r.certificate.fmt.word_bits == 16


def test_check_names_a_differing_option_by_its_keyword(tmp_path):
    out = tmp_path / "fw"
    sd.firmware.generate(sd.load_platform("utn-dynamic"), out, compile=False, length_lsb=5e-4, rate=500)
    with pytest.raises(UsageError, match=r"generated with other options \(length_lsb=0\.001 here, 0\.0005 in ") as e:
        sd.firmware.check(out / "sd_firmware.c", length_lsb=1e-3, poses=10)
    assert "--" not in str(e.value)
    with pytest.raises(UsageError, match=r"\(platform=utn-kinematic here, utn-dynamic in ") as e:
        sd.firmware.check(out / "sd_firmware.c", "utn-kinematic", poses=10)
    assert "--" not in str(e.value)
    machine = sd.load_machine(Path(__file__).parents[2] / "examples" / "newcomer-210kg.yaml")
    with pytest.raises(UsageError, match=r"\(platform=newcomer-6dof-sim here, utn-dynamic in "):
        sd.firmware.check(out / "sd_firmware.c", machine, poses=10)  # a Machine, like generate takes


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        (dict(box=["pz=1..0"]), r"^box 'pz=1\.\.0': LO and HI must be finite numbers with LO <= HI$"),
        (
            dict(box=["pz=0..5000"], length_lsb=1e-4),
            r"^box pz = 5000 mm does not fit the 16-bit pose word at this length LSB ",
        ),
        (dict(max_cells=0), r"^max_cells must be in 1\.\."),
        (dict(implementation="tp17"), r"^implementation=tp17 certifies .*; got platform=utn-dynamic$"),
    ],
)
def test_certificate_errors_name_keywords_not_flags(keywords, message):
    with pytest.raises(StewartError, match=message) as e:
        sd.firmware.certify("utn-dynamic", **keywords)
    assert "--" not in str(e.value)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["certify", "--box", "pz=1..0"], "--box 'pz=1..0': LO and HI must be finite numbers with LO <= HI"),
        (["certify", "--max-cells", "0"], "--max-cells must be in 1.."),
        (["certify", "--implementation", "tp17"], "--implementation tp17 certifies the seed's DSP firmware"),
        (["optimize", "--error-budget=-1mm"], "--error-budget must be a positive length such as 0.5mm, got '-1mm'"),
        (["generate", "--word-bits", "24", "--trig", "exact"], "--word-bits must be in 8..16 for generated C"),
        (["generate", "--length-lsb", "-1"], "--length-lsb must be > 0 m, got -1"),
        (["certify", "--rate", "-5"], "--rate must be a positive number of Hz up to 1e6, got -5"),
        (["certify", "--tick", "--tick-speed", "-1"], "--tick-speed must be >= 0, got -1"),
    ],
)
def test_the_cli_names_its_flags(tmp_path, capsys, args, message):
    rc = main(["firmware", *args, *(["--out", str(tmp_path / "fw"), "--no-compile"] if args[0] == "generate" else [])])
    err = capsys.readouterr().err
    assert rc == 2 and message in err and err.count("\n") == 1, err


def test_check_cli_names_a_differing_platform_by_its_flag(tmp_path, capsys):
    out = tmp_path / "fw"
    assert main(["firmware", "generate", "--platform", "utn-dynamic", "--out", str(out), "--no-compile"]) == 0
    rc = main(["firmware", "check", str(out / "sd_firmware.c"), "--platform", "utn-kinematic", "--poses", "10"])
    err = capsys.readouterr().err
    assert rc == 2 and "(--platform utn-kinematic here, utn-dynamic in " in err, err


# -- the run -----------------------------------------------------------------------------------------------------
def _documented_options(function) -> set[str]:
    """The names of the ``Keyword Args:`` section of ``function``'s docstring."""
    doc = inspect.getdoc(function)
    section = doc.split("Keyword Args:\n", 1)[1].split("\n\n", 1)[0]
    return set(re.findall(r"^    (\w+) \(", section, re.M))


def test_simulate_documents_every_option_of_plan_run_once():
    """``simulate`` forwards its options to ``plan_run``: its docstring documents each of ``plan_run``'s user
    keywords (``trajectory`` .. ``smooth``), and nothing else."""
    names = list(inspect.signature(plan_run).parameters)
    user = set(names[names.index("trajectory") + 1 : names.index("smooth") + 1])
    assert _documented_options(sd.simulate) == user
    assert set(inspect.signature(sd.simulate).parameters) == {"machine", "trajectory", "progress", "options"}


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        (dict(period=10.0), r"^controller\.period 10 s is too slow for platform utn-dynamic"),
        (dict(plant_step=2e-3), r"^run\.plant_step 0\.002 s is longer than the controller period 0\.001 s"),
        (dict(perod=1e-3), r"unknown key 'perod'"),
    ],
)
def test_simulate_errors_name_spec_paths_not_flags(keywords, message):
    """Refused while the run is checked, before any plant is built."""
    with pytest.raises(StewartError, match=message) as e:
        sd.simulate(sd.load_platform("utn-dynamic"), "seed", **keywords)
    assert "--" not in str(e.value)


def test_montecarlo_names_the_plant_step_by_its_flag(tmp_path, capsys):
    """The draws' timing check names ``run.plant_step``; the command, where the user typed ``--plant-step``,
    names the flag."""
    argv = ["montecarlo", "--runs", "1", "--duration", "0.05", "--plant-step", "0.01", "--no-progress"]
    rc = main([*argv, "--out", str(tmp_path / "mc")])
    err = capsys.readouterr().err
    assert rc == 2 and "--plant-step 0.01 s is longer than the controller period 0.001 s" in err, err
    assert "run.plant_step" not in err and not (tmp_path / "mc").exists()


def test_a_reference_in_the_other_unit_is_named_by_keyword_in_the_api_and_by_flag_in_the_cli(tmp_path, capsys):
    """A CSV in metres read in mm leaves the stroke: the API's hints name ``length_unit=m`` and
    ``allow_out_of_stroke=True``, the command's its flags; both refuse before any plant is built."""
    p = sd.load_platform("utn-dynamic")
    z = float(p.home_pose()[2])
    f = tmp_path / "m.csv"
    f.write_text("t,px,py,pz,a,b,g\n" + "".join(f"{i * 0.1:.1f},0,0,{z!r},0,0,0\n" for i in range(10)))
    with pytest.raises(sd.PhysicalLimitError, match=r"give length_unit=m if that is what you meant") as e:
        sd.simulate(p, str(f), length_unit="mm")
    assert "--" not in str(e.value) and "; allow_out_of_stroke=True runs it anyway" in str(e.value)
    rc = main(["simulate", "--platform", "utn-dynamic", "--trajectory", str(f), "--length-unit", "mm", "--out",
               str(tmp_path / "o"), "--no-progress"])  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 1 and "give --length-unit m if that is what you meant" in err, err
    assert "; --allow-out-of-stroke runs it anyway" in err and "allow_out_of_stroke" not in err
