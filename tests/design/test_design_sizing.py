"""Actuator sizing: trajectory sizing against an independent Newton–Euler computation from
finite differences of the pose, the envelope's worst case against random samples, the limit checks."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.core.trajectory import ROTATING
from stewart_drake.design.boxquad import box_quadratic_max
from stewart_drake.design.envelope import Envelope, EnvelopeError, cartesian_leg_forces, envelope_sizing, load_envelope
from stewart_drake.design.payload import with_payload
from stewart_drake.design.sizing import leg_motion, rotating_trajectory, size_trajectory
from stewart_drake.design.verify import newton_euler_fd, sample_box
from stewart_drake.errors import OptionError, PayloadError


@pytest.fixture(scope="module")
def loaded_platform():
    # An offset payload makes the centre of mass leave C: every coupling term of the dynamics matters.
    return with_payload(load_platform("utn-dynamic"), 3.0, [0.03, -0.02, 0.08])


def test_rotating_trajectory_is_the_simulations():
    t = np.linspace(0, 4, 101)
    assert np.abs(rotating_trajectory(t)[0] - ROTATING.pose(t)).max() < 1e-15


def test_sizing_equals_newton_euler_by_finite_differences(loaded_platform):
    p = loaded_platform
    t = np.linspace(0.0, 4.0, 401)
    q, qd, qdd = rotating_trajectory(t)
    s = size_trajectory(p, t, q, qd, qdd)
    F, L, Ld, Ldd = newton_euler_fd(p, lambda ts: rotating_trajectory(ts)[0], t)
    assert np.abs(s.force - F).max() <= 1e-6  # N: eighth-order central differences (h = 1 ms) against exact derivatives
    assert np.abs(s.speed - Ld).max() <= 1e-6  # m/s
    assert np.abs(s.length - L).max() <= 1e-12
    assert np.abs(s.accel - Ldd).max() <= 1e-6  # m/s²
    assert np.allclose(s.power, s.force * s.speed)


def test_sizing_with_translation_and_rotation(loaded_platform):
    """A trajectory moving every coordinate at once (the rotating one turns about x and z only)."""
    from stewart_drake.core.dynamics import harmonic_trajectory

    args = (
        [0.01, -0.02, 0.7, 0.02, -0.03, 0.05],
        [0.03, 0.02, 0.01, 0.06, 0.05, 0.2],
        [1.3, 2.1, 2.9, 1.7, 2.3, 3.1],
        [0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
    )
    t = np.linspace(0.0, 3.0, 301)
    q, qd, qdd = harmonic_trajectory(t, *args)
    s = size_trajectory(loaded_platform, t, q, qd, qdd)
    F, L, Ld, Ldd = newton_euler_fd(loaded_platform, lambda ts: harmonic_trajectory(ts, *args)[0], t)
    assert np.abs(s.force - F).max() <= 1e-6
    assert np.abs(s.speed - Ld).max() <= 1e-6
    assert np.abs(s.accel - Ldd).max() <= 1e-6


def test_summary_peaks_and_rms(loaded_platform):
    t = np.linspace(0.0, 4.0, 801)
    s = size_trajectory(loaded_platform, t, *rotating_trajectory(t))
    legs = s.legs()
    for i, r in enumerate(legs):
        k = r["force"]["index"]
        assert r["force"]["peak"] == np.abs(s.force[:, i]).max() == abs(s.force[k, i])
        assert r["force"]["t"] == t[k]
        assert np.isclose(r["rms_force"], np.sqrt(np.mean(s.force[:, i] ** 2)))
        assert r["min_length"] <= r["max_length"]


# ----------------------------------------------------------------------------------------------
# Envelope.


def test_box_quadratic_max_is_the_maximum():
    rng = np.random.default_rng(3)
    Q = rng.normal(size=(50, 3, 3))
    b = np.array([0.7, 1.5, 0.4])
    best, arg = box_quadratic_max(Q, b)
    grid = np.stack(np.meshgrid(*[np.linspace(-x, x, 41) for x in b], indexing="ij"), -1).reshape(-1, 3)
    vals = np.einsum("ni,kij,nj->kn", grid, Q, grid).max(1)
    assert np.all(vals <= best + 1e-12)  # no grid point beats it
    assert np.all(np.abs(arg) <= b + 1e-15)
    assert np.allclose(np.einsum("ki,kij,kj->k", arg, Q, arg), best, rtol=0, atol=1e-12)  # attained at arg
    # grid spacing h = 2b/40: the grid comes within O(|Q| h²·…) of the maximum
    assert np.all(best - vals <= 0.02)


ENV_POSES = np.array(
    [[0.0, 0.0, 0.7, 0.0, 0.0, 0.0], [0.05, -0.04, 0.72, 0.08, -0.05, 0.2], [-0.08, 0.06, 0.67, -0.05, 0.1, -0.15]]
)


@pytest.mark.parametrize("legs", [False, True])
def test_envelope_never_exceeded_and_attained(loaded_platform, legs):
    p = loaded_platform
    env = Envelope(ENV_POSES, np.array([0.3, 0.3, 0.2, 1.0, 1.5, 2.0]), np.array([3.0, 4.0, 6.0, 12.0, 10.0, 20.0]))
    es = envelope_sizing(p, env, legs=legs)
    rng = np.random.default_rng(16)
    n = 100_000
    k = rng.integers(0, len(ENV_POSES), n)
    V, A = sample_box(rng, n, env.v_max), sample_box(rng, n, env.a_max)
    F = cartesian_leg_forces(p, ENV_POSES[k], V, A, legs=legs)
    scale = np.abs(es.peak_force).max()
    tol = 1e-9 * scale  # rounding of two different evaluations of the same dynamics
    assert np.all(F <= es.force_max[k] + tol)
    assert np.all(F >= es.force_min[k] - tol)
    best = np.abs(F).max(axis=0)
    assert np.all(best >= 0.99 * es.peak_force.max(axis=0))  # attained within 1 % by a sample
    # ... and exactly at the reported maximiser
    for i, w in enumerate(es.worst):
        Fw = cartesian_leg_forces(p, w["pose"], w["velocity"], w["accel"], legs=legs)
        assert abs(Fw[i] - w["force"]) <= tol and abs(w["force"]) == w["peak"]
    # leg speed: exact worst case; leg acceleration: an upper bound
    q = ENV_POSES[k]
    qd, qdd = _to_euler(q, V, A)
    _, Ld, Ldd = leg_motion(p, q, qd, qdd)
    assert np.all(np.abs(Ld) <= es.peak_speed[k] + 1e-12)
    assert np.all(np.abs(Ld).max(0) >= 0.99 * es.peak_speed.max(0))
    assert np.all(np.abs(Ldd) <= es.peak_accel[k] + 1e-9)
    assert np.all(np.abs(F * Ld) <= es.peak_power[k] + 1e-9)


def _to_euler(q, V, A):
    from stewart_drake.design.envelope import cartesian_to_euler

    return cartesian_to_euler(q, V, A, "utn")


def test_allowed_acceleration_is_the_limit(loaded_platform):
    """At the allowed per-axis acceleration the worst leg force reaches max_force exactly (or the axis
    is unlimited); 1 % more exceeds it."""
    p = loaded_platform.replace(legs=loaded_platform.legs.__class__(max_force=60.0))
    env = Envelope(ENV_POSES, np.array([0.2, 0.2, 0.1, 0.5, 0.5, 1.0]), np.zeros(6))
    es = envelope_sizing(p, env)
    for j in range(6):
        a = np.zeros(6)
        a[j] = 1.0
        probe = Envelope(ENV_POSES, env.v_max, a * es.allowed_accel[:, j].min())
        worst = envelope_sizing(p, probe).peak_force.max()
        assert worst <= 60.0 * (1 + 1e-9)
        over = envelope_sizing(
            p, Envelope(ENV_POSES, env.v_max, a * es.allowed_accel[:, j].min() * 1.01)
        ).peak_force.max()
        assert over > 60.0


# ----------------------------------------------------------------------------------------------
# CLI.


def _write(tmp_path, name, text):
    f = tmp_path / name
    f.write_text(text)
    return str(f)


ENV_YAML = """
length_unit: mm
angle_unit: deg
box: {min: [-40, -40, 690, -4, -4, -8], max: [40, 40, 710, 4, 4, 8], steps: [2, 2, 2, 2, 2, 2]}
velocity: {linear: [200, 200, 100], angular: [20, 20, 40]}
acceleration: {linear: [2000, 2000, 4000], angular: [200, 200, 400]}
"""


def test_cli_size_trajectory_json(capsys):
    assert main(["size", "--trajectory", "rotating", "--json", "--dt", "0.01"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["legs"]) == 6
    for key in (
        "peak_force_n",
        "rms_force_n",
        "peak_speed_m_s",
        "peak_accel_m_s2",
        "peak_power_w",
        "min_length_m",
        "max_length_m",
    ):
        assert all(np.isfinite(r[key]) for r in out["legs"])
    t = np.arange(401) * 0.01
    s = size_trajectory(load_platform("utn-dynamic"), t, *rotating_trajectory(t))
    assert np.allclose([r["peak_force_n"] for r in out["legs"]], np.abs(s.force).max(0), rtol=1e-12)


def test_cli_size_program_and_envelope(tmp_path, capsys):
    assert main(["size", "--platform", "utn-kinematic", "--program", "examples/seed_004.stw", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["violation"] is None and len(out["legs"]) == 6
    env = _write(tmp_path, "env.yaml", ENV_YAML)
    assert main(["size", "--envelope", env, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["poses"] == 64
    assert len(out["allowed_acceleration"]["per_pose"]) == 64


def _platform_file(tmp_path, **legs):
    text = (load_platform_text := open("stewart_drake/presets/utn-dynamic.yaml").read())
    line = next(ln for ln in load_platform_text.splitlines() if ln.startswith("legs:"))
    new = "legs: {" + ", ".join(f"{k}: {v}" for k, v in legs.items()) + "}"
    return _write(tmp_path, "p.yaml", text.replace(line, new).replace("name: utn-dynamic", "name: limited"))


def test_cli_size_violation_is_the_first(tmp_path, capsys):
    f = _platform_file(tmp_path, max_force=2.5)
    assert main(["size", "--platform", f, "--trajectory", "rotating", "--dt", "0.01", "--json"]) == 1
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    t = np.arange(401) * 0.01
    F = size_trajectory(load_platform(f), t, *rotating_trajectory(t)).force
    k = int(np.argmax(np.any(np.abs(F) > 2.5, axis=1)))
    leg = int(np.argmax(np.abs(F[k]) > 2.5)) + 1
    v = out["violation"]
    assert (v["index"], v["leg"], v["quantity"]) == (k, leg, "force")
    assert f"first exceeded by leg {leg} " in cap.err and f"t = {t[k]:.4f} s" in cap.err
    # the message's number is the peak the table shows (issue 24, item 8: it was the first sample's value)
    kp, lp = np.unravel_index(int(np.argmax(np.abs(F))), F.shape)
    peak = max(r["peak_force_n"] for r in out["legs"])
    assert v["peak"] == pytest.approx(peak, rel=1e-12) and (v["peak_index"], v["peak_leg"]) == (kp, lp + 1)
    assert f"leg {lp + 1} force peaks at {peak:.6g} N, beyond legs.max_force 2.5 N at t = {t[kp]:.4f} s" in cap.err
    assert cap.err.count("\n") == 1


def test_cli_envelope_outside_the_stroke_is_a_result_outside_limits(tmp_path, capsys):
    """An envelope pose outside the stroke: the sizing is shown and the stroke named, exit 1 (it was exit 2,
    bad input); the library call without ``stroke=False`` still refuses it."""
    env = _write(tmp_path, "env.yaml", ENV_YAML.replace("[-40, -40, 690", "[-400, -40, 690"))
    assert main(["size", "--envelope", env, "--json"]) == 1
    cap = capsys.readouterr()
    out = json.loads(cap.out)
    v = out["violation"]
    assert v["quantity"] == "length" and len(out["legs"]) == 6 and "beyond stroke" in cap.err
    L = np.array([[r["min_length_m"], r["max_length_m"]] for r in out["legs"]])
    assert v["peak"] in L and (v["peak"] < 0.55 or v["peak"] > 0.95)
    with pytest.raises(EnvelopeError, match="leaves the workspace: leg"):
        envelope_sizing(load_platform("utn-dynamic"), load_envelope(env))


def test_cli_size_speed_limit_on_envelope(tmp_path, capsys):
    f = _platform_file(tmp_path, max_force=1000.0, max_speed=0.1)
    env = _write(tmp_path, "env.yaml", ENV_YAML)
    assert main(["size", "--platform", f, "--envelope", env]) == 1
    err = capsys.readouterr().err
    assert "speed peaks at" in err and "legs.max_speed 0.1 m/s" in err and "envelope pose 1 " in err


@pytest.mark.parametrize(
    "text, needle",
    [
        (ENV_YAML.replace("[2, 2, 2, 2, 2, 2]", "[2, 2, 2, 2, 2, 0]"), "box.steps must be >= 1"),
        (
            ENV_YAML.replace("linear: [200, 200, 100]", "linear: [200, -200, 100]"),
            "velocity.linear bounds are magnitudes",
        ),
        (ENV_YAML.replace("[2, 2, 2, 2, 2, 2]", "[300, 300, 300, 300, 2, 2]"), "more than the limit"),
        (ENV_YAML.replace("angular: [20, 20, 40]", "angular: [20, 20]"), "velocity.angular: expected 3 numbers"),
    ],
)
def test_cli_envelope_errors(tmp_path, capsys, text, needle):
    env = _write(tmp_path, "env.yaml", text)
    assert main(["size", "--envelope", env]) == 2
    err = capsys.readouterr().err
    assert needle in err and "env.yaml" in err and err.count("\n") == 1
    with pytest.raises(EnvelopeError):
        envelope_sizing(load_platform("utn-dynamic"), load_envelope(env))


@pytest.mark.parametrize(
    "args, needle",
    [
        (["--payload", "-1"], PayloadError.MASS.format(option="--payload", value="-1")),
        (
            ["--payload", "2", "--payload-com", "0", "0", "-0.01"],
            PayloadError.BELOW_PLATE.format(option="--payload-com", z=-0.01, unit="m"),
        ),
        (["--gravity", "-1"], OptionError.GRAVITY.format(option="--gravity", value="-1")),
    ],
)
def test_cli_size_bad_payload(capsys, args, needle):
    assert main(["size", "--trajectory", "seed", "--dt", "0.1"] + args) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


def test_envelope_without_velocity_is_affine(loaded_platform):
    """Zero velocity bounds: the worst case is c + Σ|G| a_max; checked against the 64 vertices."""
    env = Envelope(ENV_POSES[:1], np.zeros(6), np.array([3.0, 4.0, 6.0, 12.0, 10.0, 20.0]))
    for legs in (False, True):
        es = envelope_sizing(loaded_platform, env, legs=legs)
        signs = np.array(np.meshgrid(*[[-1.0, 1.0]] * 6, indexing="ij")).reshape(6, -1).T
        F = cartesian_leg_forces(
            loaded_platform, np.broadcast_to(ENV_POSES[0], (64, 6)), np.zeros((64, 6)), signs * env.a_max, legs=legs
        )
        assert np.allclose(F.max(0), es.force_max[0], rtol=1e-12, atol=1e-12)
        assert np.allclose(F.min(0), es.force_min[0], rtol=1e-12, atol=1e-12)


def test_cli_size_bad_limit_in_platform_file(tmp_path, capsys):
    f = _platform_file(tmp_path, max_force=100.0, max_speed=-0.5)
    assert main(["size", "--platform", f, "--trajectory", "seed", "--dt", "0.1"]) == 2
    err = capsys.readouterr().err
    assert "p.yaml:13: legs.max_speed: -0.5 must be > 0" in err and err.count("\n") == 1  # the YAML loader's field rule


def test_cli_size_trajectory_csv(tmp_path, capsys):
    """A 19-column CSV (t, q, q̇, q̈) in mm and degrees sizes like the same trajectory given directly."""
    t = np.linspace(0, 2, 201)
    q, qd, qdd = rotating_trajectory(t)
    scale = np.r_[np.full(3, 1e3), np.full(3, 180 / np.pi)]
    rows = np.concatenate([t[:, None], q * scale, qd * scale, qdd * scale], 1)
    f = tmp_path / "traj.csv"
    np.savetxt(f, rows, delimiter=",", fmt="%.17g")
    assert main(["size", "--trajectory", str(f), "--length-unit", "mm", "--angle-unit", "deg", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    s = size_trajectory(load_platform("utn-dynamic"), t, q, qd, qdd)
    assert np.allclose([r["peak_force_n"] for r in out["legs"]], np.abs(s.force).max(0), rtol=1e-12)
    assert np.allclose([r["peak_speed_m_s"] for r in out["legs"]], np.abs(s.speed).max(0), rtol=1e-12)


def test_cli_size_trajectory_below_the_base_exits_1(tmp_path, capsys):
    """A trajectory mirrored under the base keeps every leg within the stroke; the shared sanity check
    refuses it, naming the first time."""
    f = tmp_path / "below.csv"
    f.write_text("t,px,py,pz,ax,ay,az\n" + "".join(f"{0.1 * i:g},0,0,{-700 - i},0,0,0\n" for i in range(11)))
    assert main(["size", "--trajectory", str(f), "--length-unit", "mm"]) == 1
    err = capsys.readouterr().err
    assert "trajectory at t = 0.0000 s: the plate is below the base" in err and err.count("\n") == 1
