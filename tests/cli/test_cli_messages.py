"""Option and input errors of the commands: one line on stderr, exit 2, the text being the template in
``stewart_drake.errors`` filled with the value as the user typed it."""

import os

import pytest

from stewart_drake.cli import main
from stewart_drake.design.maps import MAX_POINTS
from stewart_drake.errors import CsvError, DspPoseError, OptionError, UsageError


@pytest.fixture
def short_csv(tmp_path):
    f = tmp_path / "short.csv"
    f.write_text("t,px,py,pz,a,b,g\n0,0,0,0.7,0,0,0\n0.1,0.001,0,0.7,0,0,0\n")
    return f


@pytest.fixture
def repeated_time_csv(tmp_path):
    f = tmp_path / "times.csv"
    f.write_text(
        "t,px,py,pz,a,b,g\n0,0,0,0.7,0,0,0\n0,0.001,0,0.7,0,0,0\n0.2,0.002,0,0.7,0,0,0\n0.3,0.003,0,0.7,0,0,0\n"
    )
    return f


STIFFNESS = [
    "stiffness",
    "--platform",
    "utn-dynamic",
    "--pose",
    "0",
    "0",
    "0.7",
    "0",
    "0",
    "0",
    "--length-unit",
    "m",
    "--angle-unit",
    "rad",
    "--leg-stiffness",
    "1e7",
]
CASES = [
    (["dynamics", "--platform", "utn-dynamic", "--legs", "on", "--coriolis", "off"], UsageError.LEGS_CORIOLIS),
    (
        ["dynamics", "--platform", "utn-dynamic", "--dt", "0", "--t-end", "1"],
        OptionError.DT.format(dt_name="--dt", t_end_name="--t-end", dt="0", t_end="1"),
    ),
    (
        ["workspace", "--resolution", "-1"],
        OptionError.POSITIVE.format(option="--resolution", unit="metres", value="-1"),
    ),
    (
        ["workspace", "--workers", "0"],
        OptionError.BETWEEN.format(option="--workers", lo=1, hi=4 * (os.cpu_count() or 1), value=0),
    ),
    (
        ["workspace", "--limits", "stroke,bogus"],
        OptionError.UNKNOWN_LIMIT.format(
            option="--limits", value="bogus", valid="stroke, joints, collision, dexterity"
        ),
    ),
    (
        ["size", "--platform", "utn-dynamic", "--trajectory", "seed", "--dt", "0"],
        OptionError.DT.format(dt_name="--dt", t_end_name="--t-end", dt="0", t_end="4.0"),
    ),
    (STIFFNESS + ["--gravity", "-1"], OptionError.GRAVITY.format(option="--gravity", value="-1")),
    (
        STIFFNESS + ["--map", "maps", "--map-n", "1"],
        OptionError.BETWEEN.format(option="--map-n", lo=2, hi=int(MAX_POINTS**0.5), value=1),
    ),
    (
        ["report", "--jobs", "0"],
        OptionError.BETWEEN.format(option="--jobs", lo=1, hi=4 * (os.cpu_count() or 1), value=0),
    ),
    (
        ["dsp-ik", "--pose", "0", "0", "100", "200", "0", "0", "--angle-unit", "deg"],
        DspPoseError.ANGLE_OPTION.format(name="A", value=200.0, unit="deg"),
    ),
]


@pytest.mark.parametrize("argv, message", CASES, ids=[" ".join(a[:1] + a[-2:]) for a, _ in CASES])
def test_option_errors_print_the_template(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    rc = main(argv)
    out, err = capsys.readouterr()
    name = argv[0]
    assert rc == 2 and out == "" and err == f"stewart-drake {name}: error: {message}\n"
    assert not (tmp_path / "maps").exists()  # nothing written for a refused request


def test_trajectory_csv_errors_name_the_file(short_csv, repeated_time_csv, capsys):
    assert main(["dynamics", "--platform", "utn-dynamic", "--trajectory", str(short_csv)]) == 2
    assert capsys.readouterr().err.endswith(CsvError.TOO_FEW.format(path=short_csv, need=4, got=2) + "\n")
    assert main(["dynamics", "--platform", "utn-dynamic", "--trajectory", str(repeated_time_csv)]) == 2
    message = CsvError.TIMES.format(path=repeated_time_csv, k=1, t=0.0, t_prev=0.0)
    assert capsys.readouterr().err.endswith(message + "\n")
