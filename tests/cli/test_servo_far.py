"""A servo pose far beyond the hexapod is a unit mistake (exit 2, one line), not "unreachable" with a
150-digit ratio and `inf` printed (found by the CLI fuzz at 1000 examples: ``servo --pose 0 0 1.34e157 0 0 0
--from-home``); a pose just out of reach is still a result outside limits (exit 1, every number finite)."""

from __future__ import annotations

import math
import re

import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.core.sanity import FAR_FACTOR, servo_hexapod_size
from stewart_drake.errors import StewartError
from stewart_drake.mechanisms.servo import hobby_servo_hexapod


@pytest.mark.parametrize("z", ["1.3407807929942597e+157", "1e308", "5000"])
def test_far_pose_is_a_unit_mistake(capsys, z):
    assert main(["servo", "--pose", "0", "0", z, "0", "0", "0", "--from-home"]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1, captured
    assert (
        lines[0].startswith("stewart-drake servo: error: --pose: position [0.0, 0.0, ") and "unit mistake" in lines[0]
    )


def test_the_bound_is_ten_sizes_of_the_hexapod():
    h = hobby_servo_hexapod()
    size = servo_hexapod_size(h)
    assert size >= h.arm_length + h.rod_length and size >= h.home_height  # nothing reachable lies beyond it
    sd.servo([0, 0, 0.99 * FAR_FACTOR * size, 0, 0, 0])  # within: solved (unreachable, but a result)
    with pytest.raises(StewartError, match="unit mistake"):
        sd.servo([0, 0, 1.01 * FAR_FACTOR * size, 0, 0, 0])


def test_out_of_reach_is_still_a_result_with_finite_numbers(capsys):
    assert main(["servo", "--pose", "0", "0", "300", "0", "0", "0", "--from-home"]) == 1
    out = capsys.readouterr().out
    assert "unreachable" in out and not re.search(r"\b(inf|nan)\b", out)
    ratios = [float(x) for x in re.findall(r"= ([0-9.e+]+) > 1", out)]
    assert ratios and all(math.isfinite(r) and r > 1 for r in ratios)
