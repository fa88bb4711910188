"""The motion language's bounded work: loops and moves refused before they run (static lower bounds),
durations bounded, nesting within what the Python back end can express — each with file:line:column,
exit 2, and no traceback; and the bounds never refuse a program that fits."""

import contextlib
import io
import time

import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.script import ScriptError, compile_program
from stewart_drake.script.emit import emit_python
from stewart_drake.script.interpreter import MAX_STEPS, static_cost
from stewart_drake.script.parser import MAX_LOOP_DEPTH, MAX_STMT_DEPTH, parse
from stewart_drake.script.runtime import MAX_SAMPLES, MAX_SEGMENTS, MIN_MOVE_DURATION


def cli(*argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main([str(a) for a in argv])
    return rc, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def utn():
    return load_platform("utn-kinematic")


def program(tmp_path, text, name="p.stw"):
    f = tmp_path / name
    f.write_text(text)
    return f


def test_huge_for_loop_refused_at_once(tmp_path):
    f = program(tmp_path, "x = 0\nFOR i := 1 TO 100000000 DO\n  x = i\nEND\n")
    t0 = time.process_time()
    rc, _, err = cli("run", f, "--out", tmp_path / "o")
    spent = time.process_time() - t0
    assert rc == 2 and not (tmp_path / "o").exists()
    assert err.startswith(
        f"{f}:2:1: error: this FOR loop would run 100000000 iterations, at least 200000000 steps with its body; "
        f"a program may run at most {MAX_STEPS} steps"
    )
    assert spent < 1.0  # refused before the first iteration, not after a million (CPU time, generous)


def test_nested_loops_refused_by_their_static_product(tmp_path):
    f = program(tmp_path, "FOR i := 1 TO 1000 DO\n  FOR j := 1 TO 1000 DO\n    x = j\n  END\nEND\n")
    rc, _, err = cli("run", f, "--out", tmp_path / "o")
    # steps: 1000 × (1 + [FOR statement 1 + 1000 × (1 + 1)]) = 2,002,000
    assert rc == 2 and err.startswith(
        f"{f}:1:1: error: this FOR loop would run 1000 iterations, at least 2002000 steps"
    )


def test_many_moves_refused_before_they_are_made(tmp_path):
    f = program(tmp_path, "FOR i := 1 TO 400000 DO\n  mover(0, 0, 150, 0, 0, 0) en 0.001\nEND\n")
    for cmd in (("run", f, "--out", tmp_path / "o"), ("compile", f, "--emit", "python")):
        rc, out, err = cli(*cmd)
        assert rc == 2 and out == ""
        assert err.startswith(
            f"{f}:1:1: error: this FOR loop would make 400000 moves and waits; a program may make at most {MAX_SEGMENTS}"
        )


def test_static_cost_is_a_lower_bound(utn):
    """The static estimate never exceeds what the interpreter counts (so it never refuses a program that
    fits): a loop under an IF and a WHILE counts 0, a literal nested loop its product."""
    text = (
        "n = 3\nFOR i := 1 TO 4 DO\n  FOR j := 1 TO 5 DO\n    mover(x = j) en 0.01\n  END\n"
        "  IF i > 2 THEN\n    wait 0.01\n  END\n  k = 0\n  WHILE k < n DO\n    k = k + 1\n  END\nEND\n"
    )
    prog, motion = compile_program(text, "c.stw", utn)
    steps, moves = static_cost(prog.body)
    assert moves == 20 and len(motion.segments) == 22 and moves <= len(motion.segments)
    from stewart_drake.script.check import assigned_names
    from stewart_drake.script.interpreter import _Interpreter
    from stewart_drake.script.runtime import Motion

    it = _Interpreter(Motion.at_home(utn), assigned_names(prog.body))
    it.block(prog.body)
    assert steps <= it.steps


def test_loop_just_within_the_bounds_runs(utn):
    text = f"FOR i := 1 TO {MAX_STEPS // 2 - 2} DO\nEND\n"
    compile_program(text, "ok.stw", utn)  # (count × (1 + 0)) + 1 statement < MAX_STEPS: no refusal


def test_wait_too_long_names_the_statement(tmp_path):
    f = program(tmp_path, "mover(0, 0, 150, 0, 0, 0) en 1\nwait 1e307\n")
    rc, _, err = cli("run", f, "--out", tmp_path / "o")
    assert rc == 2 and "Traceback" not in err
    assert err.startswith(
        f"{f}:2:1: error: wait lasts 1e+307 s, more than the {MAX_SAMPLES} samples a program may have at 100 Hz (20000 s)"
    )


def test_absurdly_short_move_is_an_error_at_its_place(tmp_path):
    f = program(tmp_path, "mover(0, 0, 150, 0, 0, 0) en 1\n  mover(0, 0, 160, 0, 0, 0) en 1e-200\n")
    rc, _, err = cli("run", f, "--out", tmp_path / "o")
    assert rc == 2
    assert err.startswith(
        f"{f}:2:3: error: mover duration 1e-200 s is shorter than the shortest move, {MIN_MOVE_DURATION:g} s"
    )


def _nested_ifs(n):
    return (
        "".join("  " * i + "IF 1 = 1 THEN\n" for i in range(n))
        + "  " * n
        + "x = 1\n"
        + "".join("  " * i + "END\n" for i in reversed(range(n)))
    )


def test_deep_ifs_refused_or_valid_python(tmp_path, utn):
    f = program(tmp_path, _nested_ifs(100))
    rc, out, err = cli("compile", f, "--emit", "python")
    assert rc == 2 and out == ""
    assert f"syntax error: statements nested more than {MAX_STMT_DEPTH} levels deep" in err
    ok = _nested_ifs(MAX_STMT_DEPTH - 1)
    code = emit_python(parse(ok, "ok.stw"))
    compile(code, "ok.py", "exec")  # the deepest accepted program translates to Python that parses


def test_deep_loops_refused_or_valid_python():
    def loops(n):
        return "".join("  " * i + f"FOR i{i} := 1 TO 1 DO\n" for i in range(n)) + "".join(
            "  " * i + "END\n" for i in reversed(range(n))
        )

    with pytest.raises(ScriptError, match=f"loops \\(FOR, WHILE\\) nested more than {MAX_LOOP_DEPTH} levels deep"):
        parse(loops(MAX_LOOP_DEPTH + 1), "l.stw")
    compile(emit_python(parse(loops(MAX_LOOP_DEPTH), "l.stw")), "l.py", "exec")


def test_program_below_the_base_is_refused(tmp_path):
    f = program(tmp_path, "mover(0, 0, 150, 0, 0, 0) en 1\nmover(0, 0, -100, 0, 0, 0) en 1\n")
    rc, _, err = cli("run", f, "--out", tmp_path / "o")
    assert rc == 2 and err.startswith(f"{f}:2:1: error: mover #2 to (0, 0, -100 mm; 0, 0, 0 deg) puts the plate ")
    assert "the base on platform utn-kinematic: the plate anchor of leg" in err
