"""RC-servo hexapod (seed 002): eq. 9 vs an independent root solve, pulses, limits, YAML geometry (Drake checks
and the closed loop: ``tests/drake/test_servo_drake.py``)."""

import numpy as np
import pytest
from scipy.optimize import brentq

from stewart_drake.errors import GeometryError
from stewart_drake.mechanisms.servo import (
    RATE_US_PER_RAD,
    ServoPoseError,
    anchor_positions,
    angles_from_pulses,
    arm_tips,
    hobby_servo_hexapod,
    quantise_pulses,
    solve,
)


def random_poses(h, n, seed, dx=0.008, da=np.radians(6)):
    rng = np.random.default_rng(seed)
    return h.home_pose() + np.c_[rng.uniform(-dx, dx, (n, 3)), rng.uniform(-da, da, (n, 3))]


def test_preset_dimensions_and_home(hexapod):
    # Eq. 10 by hand for servo 2: pivot (60, 25) mm, anchor at 50 mm / 50°, a = 25, s = 110 mm.
    d = 0.05 * np.array([np.cos(np.radians(50)), np.sin(np.radians(50))]) - [0.06, 0.025]
    assert hexapod.home_height == pytest.approx(np.sqrt(0.11**2 + 0.025**2 - d @ d), abs=1e-15)
    # At home the arm is at right angles to the rod (the definition behind eqs. 10-12).
    tip = arm_tips(hexapod, hexapod.home_angles)
    q = anchor_positions(hexapod, hexapod.home_pose())
    arm, rod = tip - hexapod.base_pivots, q - tip
    assert np.abs(np.einsum("ij,ij->i", arm, rod)).max() < 1e-15
    # The seed's odd/even rule (eqs. 13-14) comes out of the mounting: odd servos -1, even +1.
    assert hexapod.pulse_signs.tolist() == [-1, 1, -1, 1, -1, 1]


def test_arm_angles_match_an_independent_root_solve(hexapod):
    """Eq. 9 vs brentq on |arm tip(alpha) - anchor| - s = 0 in a ±60° bracket about alpha0 (one root there)."""
    poses = random_poses(hexapod, 200, seed=3)
    sol = solve(hexapod, poses)
    assert sol.ok.all()
    q = anchor_positions(hexapod, poses)
    worst = 0.0
    for k in range(len(poses)):
        for i in range(6):

            def f(a):
                t = arm_tips(hexapod, np.full(6, a))[i]
                return np.linalg.norm(t - q[k, i]) - hexapod.rod_length

            a0 = hexapod.home_angles[i]
            root = brentq(f, a0 - np.radians(60), a0 + np.radians(60), xtol=1e-15, rtol=1e-15)
            worst = max(worst, abs(root - sol.angles[k, i]))
    # Both are double-precision solutions of the same equation; asin near ±1 amplifies rounding a little.
    assert worst < 1e-9


def test_pulses_at_home_are_exactly_the_trims(hexapod):
    trims = [1500, 1512, 1490, 1503, 1497, 1521]
    h = hexapod.replace(neutral_us=trims)
    sol = solve(h, h.home_pose())
    assert sol.pulse.tolist() == [float(t) for t in trims]
    assert np.abs(sol.delta).max() < 1e-15


def test_pulse_formula_and_inverse(hexapod):
    poses = random_poses(hexapod, 50, seed=4)
    sol = solve(hexapod, poses)
    expect = 1500 + np.array([-1, 1, -1, 1, -1, 1]) * (sol.angles - hexapod.home_angles) * 400 / np.radians(45)
    assert np.abs(sol.pulse - expect).max() < 1e-9
    assert RATE_US_PER_RAD * np.radians(1) == pytest.approx(400 / 45)
    assert np.abs(angles_from_pulses(hexapod, sol.pulse) - sol.angles).max() < 1e-12


def test_limits_are_reported_per_servo_never_nan(hexapod):
    poses = np.array(
        [
            hexapod.home_pose() + [0, 0, 0.1, 0, 0, 0],  # far too high: rods cannot reach
            hexapod.home_pose() + [0, 0, 0.010, 0, 0, np.radians(60)],
        ]
    )  # big yaw: travel
    sol = solve(hexapod, poses)
    assert np.all(np.isfinite(sol.angles)) and np.all(np.isfinite(sol.pulse))
    v = sol.violations()
    assert [d["servo"] for d in v if d["pose"] == [0]] == [1, 2, 3, 4, 5, 6]
    assert all(d["kind"] == "unreachable" and d["ratio"] > 1 for d in v if d["pose"] == [0])
    travel = [d for d in v if d["pose"] == [1] and d["kind"] == "travel"]
    assert [d["servo"] for d in travel] == [1, 3, 5]
    assert all(d["excess_deg"] > 0 for d in travel)
    assert np.all(np.abs(sol.pulse - 1500) <= 400 + 1e-9)  # clamped to ±45°
    assert not sol.ok.any()


def test_bad_pose_is_named(hexapod):
    with pytest.raises(ServoPoseError, match=r"pose 2 has a non-finite number"):
        solve(hexapod, [hexapod.home_pose(), [0, 0, np.nan, 0, 0, 0]])
    with pytest.raises(ServoPoseError, match="needs 6 numbers"):
        solve(hexapod, [0, 0, 0.1])


def test_geometry_validation():
    with pytest.raises(GeometryError, match="must exceed the arm length"):
        hobby_servo_hexapod(rod_length=0.02)
    with pytest.raises(GeometryError, match="not symmetric"):
        h = hobby_servo_hexapod()
        h.replace(platform_anchors=h.platform_anchors + np.r_[[[0.001, 0, 0]], np.zeros((5, 3))])


def test_quantisation_rounds_half_away_from_zero():
    assert quantise_pulses([1500.4, 1500.5, 1499.5, 1234.49]).tolist() == [1500, 1501, 1500, 1234]
    with pytest.raises(ValueError, match="resolution"):
        quantise_pulses([1500], 0)


# ---- YAML geometry ----------------------------------------------------------------------------------


def test_yaml_preset_is_the_documented_layout(hexapod):
    """The shipped presets/servo-hobby.yaml (mm, paired layout) builds exactly hobby_servo_hexapod()."""
    from stewart_drake.mechanisms.servo import load_servo_hexapod

    y = load_servo_hexapod("hobby-servo")
    for name in ("base_pivots", "arm_directions", "platform_anchors", "shaft_directions", "neutral_us"):
        assert np.abs(getattr(y, name) - getattr(hexapod, name)).max() <= 1e-17, name
    for name in (
        "arm_length",
        "rod_length",
        "rate_us_per_rad",
        "travel_rad",
        "servo_torque",
        "servo_speed",
        "servo_band",
        "arm_mass",
        "rod_mass",
        "platform_mass",
    ):
        assert getattr(y, name) == pytest.approx(getattr(hexapod, name), rel=1e-15), name
    assert y.servo_speed == pytest.approx(np.radians(60) / 0.17)


def _explicit_yaml(h, trims):
    """The hexapod written in the explicit YAML layout, millimetres and degrees (repr: exact round trip)."""
    pts = lambda a: "[" + ", ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in a) + "]"  # noqa: E731
    nums = lambda a: "[" + ", ".join(repr(float(v)) for v in a) + "]"  # noqa: E731
    return (
        f"name: explicit\nlength_unit: mm\narm_length: {h.arm_length * 1e3!r}\nrod_length: {h.rod_length * 1e3!r}\n"
        f"base_pivots: {pts(h.base_pivots * 1e3)}\narm_directions_deg: {nums(np.degrees(h.arm_directions))}\n"
        f"platform_anchors: {pts(h.platform_anchors * 1e3)}\nshaft_directions: {pts(h.shaft_directions)}\n"
        f"servo: {{neutral_us: {nums(trims)}}}\n"
    )


def test_yaml_explicit_layout_round_trip(hexapod, tmp_path):
    from stewart_drake.mechanisms.servo import load_servo_hexapod

    trims = [1500, 1512, 1490, 1503, 1497, 1521]
    path = tmp_path / "mine.yaml"
    path.write_text(_explicit_yaml(hexapod, trims))
    y = load_servo_hexapod(path)
    assert y.name == "explicit" and y.neutral_us.tolist() == trims
    # mm -> m and deg -> rad round trips: a few ulps of 0.06 m / pi.
    assert np.abs(y.base_pivots - hexapod.base_pivots).max() < 1e-16
    assert np.abs(y.arm_directions - hexapod.arm_directions).max() < 1e-15
    assert np.abs(solve(y, y.home_pose()).pulse - trims).max() < 1e-9


@pytest.mark.parametrize(
    "edit, message",
    [
        (("length_unit: mm", "length_unit: inch"), "length_unit must be m or mm, got 'inch'"),
        (("arm_length: 25.0", "arm_length: -25.0"), r"arm_length must be a positive number of mm, got -25.0"),
        (
            ("speed_s_per_60deg: 0.17", "speed_s_per_60deg: 0"),
            r"servo.speed_s_per_60deg must be a positive number of seconds, got 0.0",
        ),
        (
            ("neutral_us: [1500, 1500, 1500, 1500, 1500, 1500]", "neutral_us: [1500, 1500]"),
            r"servo.neutral_us must be 6 numbers \(one per servo\), got \[1500.0, 1500.0\]",
        ),
        (("travel_deg: 45.0", "travel_deg: 95.0"), "servo.travel_deg must be below 90 degrees, got 95.0"),
        (
            ("rod_length: 110.0", "rod_length: 110.0\nbase_pivots: [[0, 0, 0]]"),
            "give either paired or the explicit layout, not both",
        ),
        (("rod_length: 110.0", "rod_length: 110.0\nrod_colour: red"), "rod_colour"),
    ],
)
def test_yaml_errors_name_the_field_and_value(tmp_path, edit, message):
    from stewart_drake.mechanisms.servo import load_servo_hexapod, servo_preset_path

    text = servo_preset_path("hobby-servo").read_text()
    assert edit[0] in text
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace(edit[0], edit[1]))
    with pytest.raises(GeometryError, match=message):
        load_servo_hexapod(path)


def test_explicit_yaml_missing_fields_and_unknown_names(hexapod, tmp_path):
    from stewart_drake.mechanisms.servo import load_servo_hexapod

    path = tmp_path / "partial.yaml"
    path.write_text(
        "\n".join(line for line in _explicit_yaml(hexapod, [1500] * 6).splitlines() if not line.startswith("shaft"))
    )
    with pytest.raises(GeometryError, match="missing shaft_directions"):
        load_servo_hexapod(path)
    with pytest.raises(GeometryError, match="unknown servo hexapod 'hobby'"):
        load_servo_hexapod("hobby")


def test_cli_platform_file(hexapod, tmp_path, capsys):
    import json

    from stewart_drake.cli import main

    path = tmp_path / "mine.yaml"
    path.write_text(_explicit_yaml(hexapod, [1510] * 6))
    assert main(["servo", "--platform", str(path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["preset"] == "explicit" and out["pulse_us"] == [1510.0] * 6
