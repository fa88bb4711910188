"""Issue 24's checks live in the API, so a Python caller gets them as the command line does: an unstable loaded
platform and a singular FK mode are results with ``ok`` False; a massless plate, unresolvable damping, a noise-
dominated trajectory file and firmware options that differ from the recorded ones raise a ``StewartError``;
``smooth=`` (the CLI's ``--smooth``) gives the true forces back."""

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.core.kinematics import leg_lengths

POSE = np.array([0.0, 0.0, 0.7, 0.0, 0.0, 0.0])
H = 1e-4  # 10 kHz


def test_stiffness_and_modes_of_an_unstable_loaded_platform_are_not_ok():
    """1e-300 N/m legs under 1 kg: K is not positive definite; no deflection is returned, ``limits`` says why.
    1 MN/m legs: stable, the deflection is a number."""
    p = sd.load_platform("utn-dynamic")
    r = sd.stiffness(p, POSE, 1e-300, payload=1.0)
    assert not r.ok and r.deflection is None and "unstable" in r.limits[0]
    assert r.to_dict()["deflection"] is None
    m = sd.modes(p, POSE, 1e-300, payload=1.0)
    assert not m.ok and "unstable" in m.limits[0]
    good = sd.stiffness(p, POSE, 1e6, payload=20.0)
    assert good.ok and good.limits == [] and abs(good.deflection[2]) < 1e-3


def test_modes_raises_for_what_the_eigen_solve_cannot_resolve():
    p = sd.load_platform("utn-dynamic")
    with pytest.raises(sd.StewartError, match="leg_damping 1e\\+300 N·s/m gives damping ratios"):
        sd.modes(p, POSE, 1e6, leg_damping=1e300)
    with pytest.raises(sd.StewartError):
        sd.modes(p.replace(mass=0.0, inertia=0.0 * p.inertia), POSE, 1e6)


def test_fk_all_modes_flags_a_pose_on_a_singularity():
    """The IK of 0 0 0.7 m, 0 0 90° on utn-dynamic: found, marked singular, and the result is not ok."""
    p = sd.load_platform("utn-dynamic")
    q = np.array([0.0, 0.0, 0.7, 0.0, 0.0, np.pi / 2])
    r = sd.fk(p, leg_lengths(p, q), all_modes=True)
    singular = [s for s in r.solutions if s.extra.get("singular")]
    assert sum(np.allclose(s.pose[:3], q[:3], atol=1e-7) for s in singular) == 1  # (and its mirror below the base)
    assert not r.ok


def _gentle_csv(path, n=6000):
    """pz = 0.7 + 0.05 sin(t) m at 10 kHz written with 6 decimals (1 µm steps)."""
    t = np.arange(n) * H
    pz = np.round(0.7 + 0.05 * np.sin(t), 6)
    path.write_text("t,px,py,pz,ax,ay,az\n" + "".join(f"{a:.4f},0,0,{z:.6f},0,0,0\n" for a, z in zip(t, pz)))
    return path


def test_noise_dominated_csv_is_refused_and_smooth_gives_the_true_forces(tmp_path):
    """Without ``smooth`` every API entry point refuses the file (its accelerations are rounding noise); with
    ``smooth=1e-6`` the forces are within 1 % of the analytic motion's (computed from exact rates)."""
    p = sd.load_platform("utn-dynamic")
    f = _gentle_csv(tmp_path / "gentle.csv")
    for call in (
        lambda: sd.inverse_dynamics(p, f),
        lambda: sd.size(p, f),
        lambda: sd.Trajectory.from_csv(f),
    ):
        with pytest.raises(sd.StewartError, match="rounded too coarsely"):
            call()
    r = sd.inverse_dynamics(p, f, smooth=1e-6)
    assert r.read_units == {"length": "m", "angle": "rad"}
    truth = sd.Trajectory("exact", lambda s: _exact(s)[0], float(r.t[-1]), exact=_exact)
    exact = sd.inverse_dynamics(p, truth, dt=H)
    assert np.abs(r.forces).max() == pytest.approx(np.abs(exact.forces).max(), rel=0.01)
    assert sd.Trajectory.from_csv(f, smooth=1e-6).duration == pytest.approx(r.t[-1])


def _exact(s):
    """``(q, q̇, q̈)`` of the gentle motion at times ``s`` (n,): pz = 0.7 + 0.05 sin(s) m."""
    s = np.asarray(s, dtype=float)
    z = np.zeros_like(s)
    return tuple(
        np.stack([z, z, v, z, z, z], axis=-1) for v in (0.7 + 0.05 * np.sin(s), 0.05 * np.cos(s), -0.05 * np.sin(s))
    )


def test_firmware_check_takes_the_recorded_options_and_refuses_others(tmp_path):
    """A module generated with a 0.5 mm LSB is checked with that LSB by default (identical); asking for 1 mm
    names the mismatch instead of reporting hundreds of differences."""
    p = sd.load_platform("utn-dynamic")
    g = sd.firmware.generate(p, tmp_path / "fw", length_lsb=5e-4, compile=False)
    source = next(f for f in g.files if f.name == "sd_firmware.c")
    assert sd.firmware.check(source, p, poses=200, duration=0.05).identical
    with pytest.raises(sd.StewartError, match="length_lsb=0.001 here, 0.0005 in"):
        sd.firmware.check(source, p, poses=200, duration=0.05, length_lsb=1e-3)
