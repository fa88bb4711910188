"""Physical sanity everywhere (``stewart_drake.core.sanity``): literal messages and exit codes for every case
of the numpy commands (plate below the base, out of stroke along a trajectory, missing plate, singular home,
non-finite or absurd options), checked against independent computations; and property
tests over random poses and trajectories: exit code in {0, 1, 2}, no traceback, no NaN/inf printed, and
exit 0 only for physically valid results."""

import contextlib
import io
import json
import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import leg_lengths, plate_anchors
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.core.trajectory import SEED
from stewart_drake.errors import FAR_CENTRE, GRAVITY_RANGE, SERVO_NEUTRAL, PhysicalLimitError, UsageError
from tests.cli._fuzz import fuzz

NOPLATE = """name: noplate
length_unit: m
utn: {b: 0.4, d: 0.1, a: 0.2}
stroke: [0.55, 0.95]
home_height: 0.7
"""

COLLINEAR = """name: collinear
length_unit: m
base_anchors: [[0, 0, 0], [0.1, 0, 0], [0.2, 0, 0], [0.3, 0, 0], [0.4, 0, 0], [0.5, 0, 0]]
top_anchors: [[0.1, 0.05, 0], [0, -0.1, 0], [0.2, 0.0, 0]]
leg_top: [0, 0, 1, 1, 2, 2]
stroke: [0.3, 1.0]
home_height: 0.6
"""


def cli(*argv):
    """``(exit code, stdout, stderr)`` of the CLI run in-process; an exception other than SystemExit
    (a traceback) fails the test."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main([str(a) for a in argv])
        except SystemExit as e:  # argparse
            rc = e.code
    return rc, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def utn():
    return load_platform("utn-kinematic")


@pytest.fixture
def noplate(tmp_path):
    f = tmp_path / "noplate.yaml"
    f.write_text(NOPLATE)
    return f


# ----------------------------------------------------------------------------------------------
# Plate above the base.


def test_ik_plate_below_base_exits_1(utn):
    rc, out, err = cli("ik", "--pose", 0, 0, -100, 0, 0, 0)
    assert rc == 1 and err == ""
    # the mirror pose has the same lengths (within stroke): only the base check can fail it
    assert np.allclose(leg_lengths(utn, pose_to_si([0, 0, -100, 0, 0, 0], "mm", "deg")), 0.473187, atol=1e-6)
    assert (
        "pose: the plate is below the base: plate anchor of leg 1 is at z = -100.000 mm (the base plane is z = 0)"
        in out
    )
    rc, out, _ = cli("ik", "--pose", 0, 0, 100, 0, 0, 0, "--json")
    assert rc == 0 and json.loads(out)["above_base"] is True


def test_ik_pose_in_metres_typed_as_mm_is_a_unit_mistake():
    rc, _, err = cli("ik", "--pose", 0, 0, 100, 0, 0, 0, "--length-unit", "m")
    assert rc == 2
    assert err.strip() == (
        "stewart-drake ik: error: --pose: position [0.0, 0.0, 100.0] m is 143 × the platform's size (0.700 m); "
        "positions beyond 10 × are surely a unit mistake (a file in mm read as metres? use --length-unit mm)"
    )


def test_ik_poses_flags_each_row_in_linear_time(tmp_path, utn):
    """Rows below the base, out of stroke and fine, flagged per row; the flags agree with an independent
    per-row computation (leg_lengths, plate anchors)."""
    rows = np.array(
        [[0, 0, 100, 0, 0, 0], [0, 0, -100, 0, 0, 0], [0, 0, 400, 0, 0, 0], [0, 0, 650, 0, 0, 0], [50, 0, 200, 5, 0, 0]]
    )
    f = tmp_path / "p.csv"
    f.write_text("px,py,pz,a,b,g\n" + "\n".join(",".join(map(str, r)) for r in rows) + "\n")
    rc, out, _ = cli("ik", "--poses", f, "--json")
    assert rc == 1
    res = json.loads(out)["results"]
    q = pose_to_si(rows.astype(float), "mm", "deg")
    L = leg_lengths(utn, q)
    z = plate_anchors(utn, q)[..., 2]
    for r, Li, zi in zip(res, L, z):
        assert r["above_base"] == bool(np.all(zi > 0))
        assert r["within_stroke"] == bool(np.all((Li >= 0.3) & (Li <= 0.7)))
        assert [v["leg"] for v in r["violations"]] == [i + 1 for i in range(6) if not 0.3 <= Li[i] <= 0.7]
    assert [r["above_base"] for r in res] == [True, False, True, True, True]
    assert [r["within_stroke"] for r in res] == [True, True, True, False, True]


def test_plate_below_base_allowed_is_a_declared_choice(tmp_path):
    f = tmp_path / "hanging.yaml"
    f.write_text(NOPLATE.replace("name: noplate", "name: hanging") + "plate_below_base_allowed: true\n")
    assert cli("ik", "--platform", f, "--pose", 0, 0, -700, 0, 0, 0)[0] == 0
    g = tmp_path / "standing.yaml"
    g.write_text(NOPLATE)
    assert cli("ik", "--platform", g, "--pose", 0, 0, -700, 0, 0, 0)[0] == 1


def test_dsp_ik_below_base_exits_1():
    rc, _, err = cli("dsp-ik", "--pose", 0, 0, -100, 0, 0, 0)
    assert rc == 1 and "--pose: the plate is below the base: plate anchor of leg 1 is at z = -100.000 mm" in err
    assert cli("dsp-ik", "--pose", 0, 0, 100, 0, 0, 0)[0] == 0


def test_fk_below_base_mode_is_not_a_success(utn):
    """The mirror assembly under the base solves the same lengths; with --initial there, Newton finds it
    and the command says so with exit 1."""
    L = leg_lengths(utn, pose_to_si([0, 0, 100, 0, 0, 0], "mm", "deg")) * 1e3
    rc, out, _ = cli("fk", "--lengths", *L, "--initial", 0, 0, -100, 0, 0, 0, "--json")
    sol = json.loads(out)["solutions"][0]
    assert sol["above_base"] is False and sol["pose"][2] == pytest.approx(-100, abs=1e-6) and rc == 1
    assert cli("fk", "--lengths", *L)[0] == 0


# ----------------------------------------------------------------------------------------------
# Trajectories: stroke and base along the way.


def test_dynamics_out_of_stroke_names_first_time_leg_amount(utn):
    q0 = SEED.pose(0.0)
    L0 = leg_lengths(utn, q0)
    leg = int(np.argmax(L0 - 0.7))
    rc, out, err = cli("dynamics", "--platform", "utn-kinematic", "--t-end", 0.2)
    assert rc == 1 and out == ""
    assert err.strip() == (
        f"stewart-drake dynamics: error: the seed trajectory leaves the stroke: first at t = 0.0000 s, leg {leg + 1} length "
        f"{L0[leg] * 1e3:.3f} mm is {(L0[leg] - 0.7) * 1e3:.3f} mm above the stroke maximum 700.000 mm; "
        "--allow-out-of-stroke runs it anyway, with a warning"
    )
    rc, out, err = cli("dynamics", "--platform", "utn-kinematic", "--t-end", 0.2, "--allow-out-of-stroke", "--json")
    assert rc == 0 and "warning: the seed trajectory leaves the stroke" in err
    assert json.loads(out)["warnings"] == [err.split("warning: ")[1].strip()]


def test_dynamics_csv_first_violation_is_the_first_in_time(tmp_path):
    """A CSV whose third sample leaves the stroke (pz 0.96 m on utn-dynamic's 0.55-0.95 m) and fourth
    dips under the base: the earliest problem is reported; below the base wins where it comes first."""
    f = tmp_path / "t.csv"
    f.write_text("t,px,py,pz,a,b,g\n0,0,0,0.7,0,0,0\n0.1,0,0,0.75,0,0,0\n0.2,0,0,0.96,0,0,0\n0.3,0,0,0.8,0,0,0\n")
    rc, _, err = cli("dynamics", "--trajectory", f)
    L = leg_lengths(load_platform("utn-dynamic"), [0, 0, 0.96, 0, 0, 0])
    assert (
        rc == 1
        and f"first at t = 0.2000 s, leg 1 length {L[0] * 1e3:.3f} mm is {(L[0] - 0.95) * 1e3:.3f} mm above" in err
    )
    g = tmp_path / "u.csv"
    g.write_text("t,px,py,pz,a,b,g\n0,0,0,0.7,0,0,0\n0.1,0,0,0.7,0,0,0\n0.2,0,0,-0.7,0,0,0\n0.3,0,0,-0.7,0,0,0\n")
    rc, _, err = cli("dynamics", "--trajectory", g)
    assert rc == 1 and "trajectory " in err and "at t = 0.2000 s: the plate is below the base" in err


# ----------------------------------------------------------------------------------------------
# Required physics, platforms.


def test_singular_home_is_refused_when_loaded_naming_the_anchors(tmp_path):
    f = tmp_path / "collinear.yaml"
    f.write_text(COLLINEAR)
    rc, _, err = cli("ik", "--platform", f, "--pose", 0, 0, 600, 0, 0, 0)
    assert rc == 2
    assert re.fullmatch(
        r"stewart-drake ik: error: platform 'collinear' is singular at its home pose \(Jacobian condition number "
        r"\S+ > 1e\+08\): base anchors 1-6 are collinear \(every leg meets one line, so the plate can turn about it\)\n",
        err,
    )


@pytest.mark.parametrize("name", ["utn-kinematic", "utn-dynamic", "gonzalez-dutra-2009"])
def test_presets_pass_their_own_sanity(name):
    from stewart_drake.core.kinematics import condition_number
    from stewart_drake.core.sanity import HOME_MAX_CONDITION, above_base, has_plate

    p = load_platform(name)
    assert (
        has_plate(p) and bool(above_base(p, p.home_pose())) and condition_number(p, p.home_pose()) < HOME_MAX_CONDITION
    )


def assert_refused_in_one_line(argv, message, tmp_path):
    """``argv`` exits 2 with ``message`` in one stderr line, no traceback, nothing on stdout; a ``simulate``
    writes no --out folder."""
    if argv[0] == "simulate":
        argv = argv + ("--out", str(tmp_path / "o"))
    rc, out, err = cli(*argv)
    assert rc == 2 and out == "" and message in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def assert_refused_before_allocation(argv, pattern, tmp_path, monkeypatch):
    """``argv`` exits 2 with an error matching ``pattern`` and nothing on stdout, before any allocation
    (the time and count bounds are checked with the memory bound lifted)."""
    import stewart_drake.core.sanity as sanity

    if "7200" in argv or "1e4" in argv:  # the time and count bounds, whatever this machine's memory
        monkeypatch.setattr(sanity, "memory_budget", lambda: 1 << 50)
    if argv[0] == "simulate":
        argv = argv + ("--out", str(tmp_path / "o"))
    rc, out, err = cli(*argv)
    assert rc == 2 and out == "" and re.search(pattern, err), err


# ----------------------------------------------------------------------------------------------
# Options: finite, in range, resolvable.


@pytest.mark.parametrize(
    "argv, message",
    [
        (("dynamics", "--gravity", "nan"), "argument --gravity: " + UsageError.NOT_FINITE_NUMBER.format(value="nan")),
        (("dynamics", "--gravity", "981"), GRAVITY_RANGE.format(option="--gravity", value="981")),
        (("dynamics", "--t-end", "inf"), "argument --t-end: " + UsageError.NOT_FINITE_NUMBER.format(value="inf")),
        (
            ("servo", "--trim", "-1500", "1500", "1500", "1500", "1500", "1500"),
            SERVO_NEUTRAL.format(
                what="--trim", servo=1, value="-1500", lo=900, hi=2100, swing=400, range_lo=500, range_hi=2500
            ),
        ),
        (
            ("servo", "--trim", "1500", "1500", "1500", "1500", "1500", "1e9"),
            "--trim: servo 6's neutral pulse 1000000000 µs is outside [900, 2100] µs",
        ),
        (
            ("servo", "--trim", "nan", "1500", "1500", "1500", "1500", "1500"),
            "argument --trim: " + UsageError.NOT_FINITE_NUMBER.format(value="nan"),
        ),
        (
            ("workspace", "--centre", "100", "0", "0"),
            FAR_CENTRE.format(option="--centre", centre="100 0 0", ratio=105, size_m=0.95, limit=10),
        ),
        (
            ("fk", "--max-iter", "1000000000", "--lengths", "500", "500", "500", "500", "500", "500"),
            "--max-iter 1000000000 would need 1e+09 Newton iterations; the limit is 1e+03 Newton iterations",
        ),
    ],
)
def test_bad_options_exit_2_with_the_message(argv, message, tmp_path):
    assert_refused_in_one_line(argv, message, tmp_path)


def test_period_bound_is_the_crossover_margin():
    """The refusal threshold follows from the stated rule: at the largest period the check accepts,
    ω_c = PHASE_BUDGET / (T + T + lag) is at least 2 × the fastest growth rate, and just above it, below."""
    from stewart_drake.control import CROSSOVER_MARGIN, PHASE_BUDGET, check_timing
    from stewart_drake.core.dynamics import open_loop_growth_rates
    from stewart_drake.errors import StewartError

    p = load_platform("utn-dynamic")
    lam = max(open_loop_growth_rates(p, p.home_pose()))
    lag = 2e-3
    T_max = (PHASE_BUDGET / (CROSSOVER_MARGIN * lam) - lag) / 2  # output delay = one period ('sample' latency)
    check_timing(p, T_max * 0.999, 1e-3, lag, T_max * 0.999)
    with pytest.raises(StewartError, match="too slow"):
        check_timing(p, T_max * 1.001, 1e-3, lag, T_max * 1.001)


def test_leg_fk_outside_joint_limits_exits_1():
    rc, out, _ = cli("leg", "fk", 500, 10)
    assert rc == 1 and "(outside joint limits)" in out
    assert cli("leg", "fk", 10, 10)[0] == 0


# ----------------------------------------------------------------------------------------------
# Workspace: the half-space above the base; bounded grids.


def test_workspace_counts_only_above_the_base(utn):
    """utn-kinematic's stroke workspace reaches the base plane; its mirror image under the base is not
    counted: z from 0, and the volume equals the exact column integral above the plate floor."""
    from stewart_drake.workspace import stroke_volume_columns

    rc, out, _ = cli("workspace", "--platform", "utn-kinematic", "--json", "--resolution", 0.01)
    w = json.loads(out)
    assert rc == 0 and w["z_range"][0] >= 0.0 and w["z_range"][0] == pytest.approx(0.0, abs=1e-9)
    v_col = stroke_volume_columns(utn, 0.004)
    lo, hi = w["volume_bounds_m3"]
    assert lo <= v_col <= hi
    full = stroke_volume_columns(utn, 0.004, z_floor=-1.0)  # with the mirror: twice as much
    assert full == pytest.approx(2 * v_col, rel=1e-3)


@pytest.mark.parametrize("h", ["1e-9", "1e-8", "1e-4"])
def test_workspace_resolution_refused_before_allocating(h):
    import tracemalloc

    tracemalloc.start()
    rc, _, err = cli("workspace", "--resolution", h)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert rc == 2 and peak < 50e6
    assert re.search(
        rf"resolution {float(h):g} m would need \S+ grid nodes \(~\S+ GB\); the finest this machine can hold is ~[0-9.]+ mm; "
        r"use a coarser --resolution",
        err,
    )


# ----------------------------------------------------------------------------------------------
# Bounded work: durations, steps.


@pytest.mark.parametrize(
    "argv, pattern",
    [
        (
            ("dynamics", "--t-end", "1e9", "--dt", "1e-6"),
            r"--t-end/--dt 1000000000/1e-06 s would need 1e\+15 samples \(~10\^\d+ GB\); the limit is \S+ GB on this machine; use a larger --dt",
        ),
        (("dynamics", "--t-end", "1e4", "--dt", "1e-4"), r"would need 1e\+08 samples; the limit is 1e\+07 samples"),
    ],
)
def test_work_is_bounded_before_allocation(argv, pattern, tmp_path, monkeypatch):
    assert_refused_before_allocation(argv, pattern, tmp_path, monkeypatch)


# ----------------------------------------------------------------------------------------------
# Property tests: random poses and trajectories.

finite = st.floats(-2000, 2000, allow_nan=False)
anything = st.one_of(finite, st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, 0.0, -100.0]))
NUMBER = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)


POSE = (st.lists(anything, min_size=6, max_size=6), st.sampled_from(["mm", "m"]))


@settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(*POSE)
def test_ik_any_pose(pose, unit):
    check_ik_pose(pose, unit)


@fuzz
@given(*POSE)
def test_ik_any_pose_fuzz(pose, unit):
    check_ik_pose(pose, unit)


def check_ik_pose(pose, unit):
    p = load_platform("utn-kinematic")
    # fixed notation: argparse takes "-1e-05" (and "-inf") for an option (its usage error is exit 2 too)
    rc, out, err = cli(
        "ik", "--pose", *[f"{v:.330f}" if math.isfinite(v) else repr(v) for v in pose], "--length-unit", unit, "--json"
    )
    assert rc in (0, 1, 2) and "Traceback" not in err
    assert not NUMBER.search(out)
    if rc == 2:
        assert err.splitlines()[-1].startswith("stewart-drake ik: error: ") and out == ""
        return
    q = pose_to_si(np.array(pose), unit, "deg")
    L = leg_lengths(p, q)
    valid = bool(np.all((L >= p.L_min) & (L <= p.L_max)) and np.all(plate_anchors(p, q)[:, 2] > 0))
    assert (rc == 0) == valid
    assert json.loads(out)["lengths"] == pytest.approx((L * (1e3 if unit == "mm" else 1)).tolist(), rel=1e-12)


SAMPLES = st.lists(
    st.tuples(
        st.floats(-0.3, 0.3),
        st.floats(-0.3, 0.3),
        st.sampled_from([0.7, 0.6, 0.9, -0.7, 0.0, 7.0, math.nan]),
        st.floats(-0.5, 0.5),
    ),
    min_size=4,
    max_size=6,
)


@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
@given(SAMPLES)
def test_dynamics_any_trajectory(tmp_path, samples):
    check_dynamics_trajectory(tmp_path, samples)


@fuzz
@given(SAMPLES)
def test_dynamics_any_trajectory_fuzz(tmp_path, samples):
    check_dynamics_trajectory(tmp_path, samples)


def check_dynamics_trajectory(tmp_path, samples):
    """Random 4-6 sample CSV trajectories (positions within, beyond and below the stroke, non-finite):
    exit 0 only when every sample is within stroke and above the base, and then finite forces."""
    p = load_platform("utn-dynamic")
    rows = [f"{0.1 * k},{x},{y},{z},{a},0,0" for k, (x, y, z, a) in enumerate(samples)]
    f = tmp_path / "t.csv"
    f.write_text("t,px,py,pz,a,b,g\n" + "\n".join(rows) + "\n")
    rc, out, err = cli("dynamics", "--trajectory", f, "--json")
    assert rc in (0, 1, 2) and "Traceback" not in err and not NUMBER.search(out)
    if rc != 0:
        assert out == "" and err.count("\n") == 1
        return
    q = np.array([[x, y, z, a, 0, 0] for x, y, z, a in samples])
    from scipy.interpolate import CubicSpline

    qs = CubicSpline(0.1 * np.arange(len(q)), q, axis=0)(0.1 * np.arange(len(q)))
    L = leg_lengths(p, qs)
    assert np.all((L >= p.L_min) & (L <= p.L_max)) and np.all(plate_anchors(p, qs)[..., 2] > 0)
    assert np.all(np.isfinite(json.loads(out)["forces"]))


def test_physical_limit_error_exits_1():
    assert PhysicalLimitError.exit_code == 1


def test_run_without_plate_computes_no_forces_and_says_so(noplate, tmp_path):
    f = tmp_path / "p.stw"
    f.write_text("mover(0, 0, 750, 0, 0, 0) en 1\n")
    rc, out, _ = cli("run", f, "--platform", noplate, "--out", tmp_path / "o", "--json")
    s = json.loads(out)
    assert rc == 0 and s["max_abs_force_N"] is None
    assert s["notes"] == ["leg forces not computed: platform 'noplate' has no plate mass properties (YAML key 'plate')"]


def test_workspace_workers_bounded():
    import os

    n = 4 * (os.cpu_count() or 1) + 1
    rc, _, err = cli("workspace", "--workers", n)
    assert rc == 2 and f"--workers must be between 1 and {n - 1}, got {n}" in err


def test_rotation_limits_stop_at_the_base_plane(utn):
    """utn-kinematic at home (pz = 100 mm) tilted about X: a plate anchor at y = ±a/2 = ±306.25 mm
    reaches the base plane when 100 mm + 306.25 mm · sin θ = 0, θ = asin(100 / 306.25) = 19.058°, far
    before any stroke limit."""
    from stewart_drake.workspace import orientation_limits

    lim = {(r.axis, r.sign): r for r in orientation_limits(utn)}
    theta = math.asin(0.1 / (0.6125 / 2))
    for s in (1, -1):
        r = lim[("x", s)]
        assert r.limit == "base" and r.angle == pytest.approx(s * theta, abs=1e-8)
    assert lim[("z", 1)].limit == "stroke"  # a turn about the vertical never lowers the plate
