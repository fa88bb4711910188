"""Messages that cannot mislead: a negative number in exponent form is a value, not an option; the
--workspace count is the one the option takes; Newton's fk at a pose on a singularity says SINGULAR."""

import json

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.newton_fk import jacobian_analysis, multiple_root


def test_a_negative_number_with_an_exponent_is_a_value(capsys):
    """``-1e-3`` after an option taking numbers is read as the number (argparse's own matcher knows only
    the ``-1`` and ``-.5`` forms); the pose echoed back carries it."""
    assert main(["ik", "--platform", "utn-dynamic", "--pose", "0", "0", "700", "-1e-3", "-2E-2", "0", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["pose"] == [0, 0, 700, -1e-3, -2e-2, 0]


def test_a_negative_exponent_value_meets_the_options_own_check(tmp_path, capsys):
    assert main(["firmware", "generate", "--length-lsb", "-1e-3", "--out", str(tmp_path / "fw")]) == 2
    err = capsys.readouterr().err
    assert "error: --length-lsb must be > 0 m, got -1e-3" in err and "expected one argument" not in err
    assert not (tmp_path / "fw").exists()


def test_workspace_message_asks_for_four_numbers(tmp_path, capsys):
    assert (
        main(["plan-measurements", "--poses", "30", "--workspace", "10", "10", "0", "5", "--out", str(tmp_path)]) == 2
    )
    err = capsys.readouterr().err
    assert "--workspace 10 10 0 5: give four numbers X Y Z ROT" in err and "six" not in err


SINGULAR_POSE = [0, 0, 0.7, 0, 0, np.pi / 2]  # utn-dynamic: the 3-6 platform turned 90° about z, on a singularity


def test_newton_fk_at_a_singular_pose_says_singular_and_exits_1(capsys):
    """The lengths of a pose on a singularity: Newton converges (linearly) to it; the result is shown with
    SINGULAR and exit 1, as ``--all`` does; a regular pose is neither."""
    lengths = leg_lengths(load_preset("utn-dynamic"), np.array(SINGULAR_POSE)) * 1e3
    assert main(["fk", "--platform", "utn-dynamic", "--lengths", *map(repr, lengths.tolist())]) == 1
    out, err = capsys.readouterr()
    assert "SINGULAR (a multiple root" in out and "lie on a singularity" in err
    regular = leg_lengths(load_preset("utn-dynamic"), np.array([0.01, 0, 0.72, 0.05, 0, 0.2])) * 1e3
    assert main(["fk", "--platform", "utn-dynamic", "--lengths", *map(repr, regular.tolist())]) == 0
    assert "SINGULAR" not in capsys.readouterr().out


@pytest.mark.parametrize("tol", [1e-13, 1e-9])
def test_multiple_root_test_tells_the_singular_pose_from_its_neighbours(tol):
    """At the singular pose σ_min is 0; 1 mrad away (well outside what a tolerance of 1e-9 m leaves at a
    double root: d ~ √(2·tol/K), ~1e-4 for K ~ 10 /m), it is a simple root."""
    p = load_preset("utn-dynamic")
    assert multiple_root(p, SINGULAR_POSE, 0.0, tol)
    near = np.array(SINGULAR_POSE) + [0, 0, 0, 0, 0, 1e-2]
    assert not multiple_root(p, near, float(jacobian_analysis(p, near).sigma_min), tol)
