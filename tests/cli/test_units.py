"""One unit rule (issue 24, item 4): outputs name the units they read, and a pose outside the workspace in
the unit read but inside it in the other unit says so, both ways."""

import json
from pathlib import Path

from stewart_drake.cli import main

NEWCOMER = str(Path(__file__).parents[2] / "examples" / "newcomer-150kg.yaml")  # a metre file


def test_ik_header_names_the_units_read(capsys):
    assert main(["ik", "--platform", NEWCOMER, "--pose", "0", "0", "1100", "0", "0", "0"]) == 0
    assert capsys.readouterr().out.startswith(
        "platform newcomer-150kg, convention utn, poses read in mm and deg, lengths in mm"
    )
    assert main(["ik", "--platform", NEWCOMER, "--pose", "0", "0", "1100", "0", "0", "0", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert (res["length_unit"], res["angle_unit"]) == ("mm", "deg")


def test_metres_typed_as_millimetres_are_named(capsys):
    """0 0 1.1 on a metre platform was read as 1.1 mm: "176.592 mm below L_min" and no hint before."""
    assert main(["ik", "--platform", NEWCOMER, "--pose", "0", "0", "1.1", "0", "0", "0"]) == 1
    err = capsys.readouterr().err
    assert "read in mm; read in m every pose would be inside the workspace: give --length-unit m" in err


def test_degrees_typed_as_radians_are_named(capsys):
    """5° of roll written in a rad command: 5 rad puts legs outside the stroke; in degrees it is inside."""
    argv = ["ik", "--platform", NEWCOMER, "--pose", "0", "0", "1200", "5", "0", "0", "--angle-unit", "rad"]
    assert main(argv) == 1
    assert "read in rad; read in deg every pose would be inside the workspace" in capsys.readouterr().err
    assert main([*argv[:-2], "--angle-unit", "deg"]) == 0


def test_millimetres_in_a_metre_trajectory_read_as_mm_are_named(tmp_path, capsys):
    """The other direction: a trajectory in metres read with --length-unit mm leaves the stroke; the message
    names metres, and the output header of a good run names the units read."""
    f = tmp_path / "m.csv"
    f.write_text("t,px,py,pz,ax,ay,az\n" + "".join(f"{i * 0.1:.1f},0,0,1.2,0,0,0\n" for i in range(30)))
    assert main(["dynamics", "--platform", NEWCOMER, "--trajectory", str(f), "--length-unit", "mm"]) == 1
    assert "read in mm; read in m every pose would be inside the workspace" in capsys.readouterr().err
    assert main(["dynamics", "--platform", NEWCOMER, "--trajectory", str(f)]) == 0
    assert "(read in m and rad)" in capsys.readouterr().out.splitlines()[0]
