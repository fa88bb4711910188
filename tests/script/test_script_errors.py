"""Diagnostics of the motion language: exact message and position for every kind of error, several
errors reported together, and nothing written (no traceback) when a program is wrong."""

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.script import ScriptError, ScriptErrors, run_program


@pytest.fixture(scope="module")
def utn():
    return load_preset("utn-kinematic")


def error_of(src, platform):
    with pytest.raises(ScriptError) as info:
        run_program(src, "t.stw", platform)
    return str(info.value)


CASES = [
    # syntax: file:line:column, the offending token, the expected tokens
    (
        "x = (1 + 2",
        "t.stw:1:11: syntax error: unexpected end of file; expected one of: ')', AND, OR, a comparison (= <> < <= > >=)",
    ),
    (
        "x = 3 $ 4",
        "t.stw:1:7: syntax error: unexpected character '$'; expected one of: '*', '+', '-', '/', ';', DIV, FOR, IF, MOD, WHILE, a name, end of file, mover, units, wait",
    ),
    (
        "x = 1\ny = end",
        "t.stw:2:5: syntax error: unexpected keyword 'end'; expected one of: '(', '+', '-', a name, a number",
    ),
    (
        "mover(1, 2 3)",
        "t.stw:1:12: syntax error: unexpected number 3; expected one of: ')', '*', '+', ',', '-', '/', DIV, MOD",
    ),
    (
        "FOR i := 1 TO 3 DO\n  wait 1\n",
        "t.stw:3:1: syntax error: unexpected end of file; expected one of: END, FOR, IF, WHILE, a name, mover, units, wait",
    ),
    (
        "x = 1 < 2",
        "t.stw:1:7: syntax error: unexpected '<'; expected one of: ';', FOR, IF, WHILE, a name, end of file, mover, units, wait",
    ),
    (
        "LOOP",
        "t.stw:1:1: error: 'LOOP' is a reserved word (Modula-2, kept from seed 004's Stewart.g) and cannot be used yet",
    ),
    ("x = 1e999", "t.stw:1:5: error: number 1e999 is too large"),
    # undefined variables
    ("x = yy + 1", "t.stw:1:5: error: undefined variable 'yy': it is never assigned in this program"),
    (
        "alpha = 1\nz = alpah",
        "t.stw:2:5: error: undefined variable 'alpah': it is never assigned in this program (did you mean 'alpha'?)",
    ),
    (
        "y = x\nx = 1",
        "t.stw:1:5: error: undefined variable 'x': it is first assigned at line 2, column 1, after this use",
    ),
    # argument lists
    ("mover(1, 2, 3)", "t.stw:1:1: error: mover takes 6 arguments (x, y, z, alpha, beta, gama), got 3"),
    ("move(1, 2, 3, 4, 5, 6, 7)", "t.stw:1:1: error: move takes 6 arguments (x, y, z, alpha, beta, gama), got 7"),
    ("mover()", "t.stw:1:1: error: mover takes 6 arguments (x, y, z, alpha, beta, gama), got 0"),
    ("mover(x=1, w=2)", "t.stw:1:12: error: mover has no argument 'w'; its arguments are x, y, z, alpha, beta, gama"),
    ("mover(x=1, x=2)", "t.stw:1:12: error: mover: argument 'x' given twice"),
    ("mover(1, x=2)", "t.stw:1:10: error: mover: argument 'x' given twice"),
    ("mover(z=1, 2)", "t.stw:1:12: error: mover: positional argument after a keyword argument"),
    ("x = sin(1, 2)", "t.stw:1:5: error: sin() takes 1 argument, got 2"),
    ("x = atan2(1)", "t.stw:1:5: error: atan2() takes 2 arguments, got 1"),
    (
        "x = foo(1)",
        "t.stw:1:5: error: unknown function 'foo'; available: abs, acos, asin, atan, atan2, cos, max, min, sin, sqrt, tan",
    ),
    # types, units, values
    ("IF 1 THEN END", "t.stw:1:4: error: IF needs a condition such as x > 0, got a number"),
    ("x = (1 < 2) + 1", "t.stw:1:6: error: '+' needs a number, got a condition"),
    (
        "units mm, kg",
        "t.stw:1:11: error: units: 'kg' is not a unit; expected m or mm (length), rad or deg or pi (angle)",
    ),
    ("units mm, m", "t.stw:1:11: error: units: two length units given ('mm' and 'm')"),
    ("pi = 3", "t.stw:1:1: error: cannot assign to the constant 'pi'"),
    ("x = 1 / (2 - 2)", "t.stw:1:7: error: division by zero (1 / 0)"),
    ("x = 5 MOD 0", "t.stw:1:7: error: division by zero (5 MOD 0)"),
    ("x = sqrt(-1)", "t.stw:1:5: error: sqrt(-1) has no finite value"),
    ("x = 1e300 * 1e300", "t.stw:1:11: error: arithmetic overflow: 1e+300 * 1e+300 is not finite"),
    ("FOR i := 1 TO 2 BY 0 DO END", "t.stw:1:1: error: FOR step is 0: the loop would never end"),
    ("mover(0, 0, 100, 0, 0, 0) en -1", "t.stw:1:1: error: mover duration must be positive, got -1 s"),
    ("wait -1", "t.stw:1:1: error: wait duration must be >= 0, got -1 s"),
    (
        "WHILE 1 < 2 DO END",
        "t.stw:1:1: error: the program ran more than 1000000 steps (statements and loop iterations); does a loop never end?",
    ),
]


@pytest.mark.parametrize("src, message", CASES, ids=[c[0].split("\n")[0] for c in CASES])
def test_error_message_and_position(src, message, utn):
    assert error_of(src, utn) == message


def test_unreachable_pose_names_the_mover_the_leg_and_the_amount(utn):
    """Leg 4 of the seed's pose is 693.56 mm; 30 mm higher it passes the 700 mm stroke end. The excess
    is checked against an independent IK call."""
    src = "x = 100\nmover(0, 0, 150, 0, 0, 0)\nmover(x, 120, 330, 25, 10, 0) en 2\nwait 1"
    L = leg_lengths(utn, pose_to_si([100, 120, 330, 25, 10, 0], "mm", "deg")) * 1e3
    leg = int(np.argmax(L - 700))
    assert leg == 3
    assert error_of(src, utn) == (
        f"t.stw:3:1: error: mover #2 to (100, 120, 330 mm; 25, 10, 0 deg) is out of reach on platform utn-kinematic: "
        f"leg 4 would be {L[leg] - 700:.3f} mm above the stroke maximum 700.000 mm (length {L[leg]:.3f} mm at t = 3.000 s)"
    )


def test_unreachable_below_the_stroke(utn):
    """x = 250 mm at the home height shortens leg 1 to 293.5 mm, below the 300 mm minimum (and no
    leg is too long)."""
    msg = error_of("mover(250, 0, 100, 0, 0, 0)", utn)
    L = leg_lengths(utn, pose_to_si([250, 0, 100, 0, 0, 0], "mm", "deg")) * 1e3
    assert L.max() < 700 and np.argmin(L) == 0
    assert msg == (
        "t.stw:1:1: error: mover #1 to (250, 0, 100 mm; 0, 0, 0 deg) is out of reach on platform utn-kinematic: "
        f"leg 1 would be {300 - L[0]:.3f} mm below the stroke minimum 300.000 mm (length {L[0]:.3f} mm at t = 1.000 s)"
    )


def test_unreachable_only_on_the_way_there(utn):
    """Both poses are within the stroke, but the straight path between them (in pose coordinates)
    takes a leg past 700 mm: the check is made on every sample, and says the violation is on the way.
    (Poses with every plate anchor above the base plane all along, as ``sanity.above_base`` requires.)"""
    a, b = [-150, 60, 246, -19, -15, 12], [-85, 75, 181, 23, 9, 13]
    ends = leg_lengths(utn, pose_to_si(np.array([a, b]), "mm", "deg")) * 1e3
    assert np.all((ends > 300) & (ends < 700))
    src = f"mover({', '.join(map(str, a))}) en 1\nmover({', '.join(map(str, b))}) en 1"
    msg = error_of(src, utn)
    assert msg.startswith("t.stw:2:1: error: mover #2 to (-85, 75, 181 mm; 23, 9, 13 deg) is out of reach")
    assert msg.endswith(", on the way there)")


def test_several_errors_are_reported_together(utn):
    with pytest.raises(ScriptErrors) as info:
        run_program("x = q\nmover(1, 2)\ny = sin(1, 2)", "t.stw", utn)
    assert str(info.value).splitlines() == [
        "t.stw:1:5: error: undefined variable 'q': it is never assigned in this program",
        "t.stw:2:1: error: mover takes 6 arguments (x, y, z, alpha, beta, gama), got 2",
        "t.stw:3:5: error: sin() takes 1 argument, got 2",
    ]


def test_render_shows_the_line_and_a_caret(utn):
    with pytest.raises(ScriptError) as info:
        run_program("x = 1\ny = (x + 2", "t.stw", utn)
    assert info.value.render().splitlines()[1:] == ["    y = (x + 2", "              ^"]


def test_cli_reports_errors_without_traceback_and_writes_nothing(tmp_path, capsys, utn):
    prog = tmp_path / "bad.stw"
    prog.write_text("x = 100\nmover(x, 0, 100, 0, 0)\nmover(0, 0, 900, 0, 0, 0)\n")
    out = tmp_path / "out"
    assert main(["run", str(prog), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{prog}:2:1: error: mover takes 6 arguments (x, y, z, alpha, beta, gama), got 5" in err
    assert "Traceback" not in err
    assert not out.exists()
    # Fixed arity, the unreachable pose is reported (by the run) and still nothing is written.
    prog.write_text("x = 100\nmover(x, 0, 100, 0, 0, 0)\nmover(0, 0, 900, 0, 0, 0)\n")
    assert main(["run", str(prog), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert (
        f"{prog}:3:1: error: mover #2 to (0, 0, 900 mm; 0, 0, 0 deg) is out of reach on platform utn-kinematic: leg 1"
        in err
    )
    assert not out.exists()
    target = tmp_path / "bad.py"
    assert main(["compile", str(prog), "--emit", "python", "-o", str(target)]) == 2
    assert not target.exists()


def test_cli_missing_program_is_one_line(tmp_path, capsys):
    assert main(["run", str(tmp_path / "nope.stw")]) == 2
    assert "does not exist" in capsys.readouterr().err
