"""The section "The loop": its grid of poses over the workspace box, its margins equal to ``sd.loop_response``
recomputed at the poses it names, a machine whose margins miss the 6 dB / 30° rule shown as a failed check (a
finding, not an error), and its fine format and ripple sweep's LSBs."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.analyses import the_loop
from stewart_drake.control.frequency import MIN_GAIN_MARGIN_DB, MIN_PHASE_MARGIN_DEG
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.report import Section
from stewart_drake.spec import Gains, load_machine


def test_the_grid_is_the_box_centre_and_its_face_centres_within_the_stroke():
    """utn-dynamic states no box: home ± 10 % of the stroke range on x, y, z and ±15° on each angle; each face pose
    moves one coordinate by that much; every pose kept has its legs within the stroke, every pose dropped does not."""
    p = load_preset("utn-dynamic")
    names, poses = the_loop.pose_grid(p)
    assert names[0] == "centre" and np.array_equal(poses[0], p.home_pose())
    half = np.r_[[0.1 * (p.L_max - p.L_min)] * 3, [math.radians(15)] * 3]
    for name, q in zip(names[1:], poses[1:]):
        k = the_loop.AXES.index(name[0])
        d = q - p.home_pose()
        assert np.count_nonzero(d) == 1 and d[k] == pytest.approx((1 if name[1] == "+" else -1) * half[k], rel=1e-12)
    L = leg_lengths(p, poses)
    assert np.all((L >= p.L_min) & (L <= p.L_max))
    # the 13 candidate poses by hand: the ones left out are exactly those with a leg beyond the stroke
    cand = [p.home_pose()] + [p.home_pose() + s * half[k] * np.eye(6)[k] for k in range(6) for s in (-1, 1)]
    Lc = leg_lengths(p, np.array(cand))
    assert len(names) == int(np.all((Lc >= p.L_min) & (Lc <= p.L_max), axis=1).sum())


def test_margins_equal_loop_response_recomputed_and_a_failing_machine_is_a_failed_check():
    """gonzalez-dutra-2009 with its designed gains misses the rule (a real finding: the section must report it, not
    raise); the section's numbers are ``sd.loop_response``'s at the poses it names, with the same explicit gains."""
    machine, _ = the_loop._study_machine("gonzalez-dutra-2009")
    assert isinstance(machine.controller.gains, Gains)
    rows = the_loop.workspace_margins(machine, full=False)
    section = Section("The loop", quick=True)
    the_loop.margin_checks(section, "gd", rows)
    gm_check, pm_check = section.checks[1], section.checks[2]
    # recomputed independently of the section's bookkeeping: the smallest margins over legs and poses
    again = [sd.loop_response(machine, q) for q in the_loop.pose_grid(machine.loaded_platform, full=False)[1]]
    gm = min(min(m["gain_margin_db"] for m in r.margins) for r in again)
    pm = min(min(m["phase_margin_deg"] for m in r.margins) for r in again)
    assert gm_check.worst == pytest.approx(MIN_GAIN_MARGIN_DB - gm, abs=1e-12)
    assert pm_check.worst == pytest.approx(MIN_PHASE_MARGIN_DEG - pm, abs=1e-12)
    assert not gm_check.passed and not pm_check.passed  # the finding: GM ~1 dB, PM ~4°
    named = min(rows, key=lambda r: r["gm"])["pose"]
    assert f"at {named})" in gm_check.what
    assert section.checks[0].passed  # stable at these poses: the margins are the loop's


def test_the_fine_format_holds_the_stroke_in_sixteen_bits_and_the_sweep_is_ascending():
    """The fine LSB is the smallest whole number of sensor counts whose 16-bit words reach the stroke's end."""
    m = load_machine("utn-dynamic")
    lsb, r = the_loop.fine_lsb(m), m.sensors.resolution
    words = 2**15 - 1
    assert words * lsb >= m.loaded_platform.L_max > words * (lsb - r)
    assert round(lsb / r) * r == pytest.approx(lsb, rel=1e-12)
    sweep = the_loop.ripple_lsbs(m)
    assert sweep == sorted(sweep) and sweep[0] == lsb and m.firmware.length_lsb in sweep


def test_actuators_as_the_machine_states_them(tmp_path):
    """The lag and the force limit where the machine file sets them (``actuators.max_force`` over
    ``legs.max_force``)."""
    m = load_machine("utn-dynamic", {"actuators.time_constant": "5ms", "actuators.max_force": "150N"})
    rows = {r[0]: r for r in the_loop.actuator_rows(m)}
    assert rows["time constant τ"][1] == pytest.approx(5.0)
    assert rows["force limit"][1:] == [150.0, "N", "actuators.max_force"]
    assert rows["the command's full scale (Q15)"][1] == m.loaded_platform.legs.max_force


@pytest.mark.parametrize("model", ["screw", "hydraulic"])
def test_the_actuator_rows_list_every_parameter_of_a_screw_or_cylinder_with_its_unit(model):
    """A screw's or cylinder's rows: the model, then each resolved parameter (as ``actuators.screw``/``hydraulic``
    give them) with a unit and where it is set (the file's field, or its default), then the command's scale."""
    machine = load_machine(
        "utn-dynamic",
        {
            "actuators.model": model,
            "actuators.efficiency" if model == "screw" else "actuators.leakage": 0.8 if model == "screw" else 1e-12,
        },
    )
    rows = the_loop.actuator_rows(machine)
    a = machine.actuators
    params = a.screw(machine.platform.legs.max_force) if model == "screw" else a.hydraulic(machine.platform)
    names = [f.name for f in dataclasses.fields(params)]
    assert rows[0][2:] == ["", "actuators.model"] and rows[-1][0].startswith("the command's full scale")
    assert [r[0] for r in rows[1:-1]] == [n.replace("_", " ") for n in names]
    assert [r[1] for r in rows[1:-1]] == [getattr(params, n) for n in names]
    assert all(the_loop.PARAMETER_UNITS.get(n, "") or n == "efficiency" for n in names)
    given = "efficiency" if model == "screw" else "leakage"
    assert {r[0]: r[3] for r in rows[1:-1]}[given] == f"actuators.{given}"
