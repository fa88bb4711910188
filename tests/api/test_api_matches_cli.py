"""The API and the command line give the same numbers: for every command with ``--json`` that has an API
function, the test calls the API in SI units and the CLI in its own units (mm, degrees where it takes them), on a
preset and on a YAML platform of the test's own, and compares them after converting the API's numbers here
(independently of the CLI's conversion code).

Tolerance: the CLI's numbers are the API's multiplied or divided by 1000 or π/180 once: a few ulps, so 1e-12
relative (+1e-15 absolute for values that should be 0). The typed inputs are converted to SI by the same
products (× 1e-3, × π/180) so that both sides compute from the same floats.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main

RTOL, ATOL = 1e-12, 1e-15
MM, DEG = 1e3, 180.0 / math.pi

OWN_YAML = """\
name: api-test-radial
description: "a 6-6 platform of the API test's own"
length_unit: mm
radial:
  base_radius: 560.0
  base_angles_deg: [280.0, 20.0, 40.0, 140.0, 160.0, 260.0]
  top_radius: 350.0
  top_angles_deg: [315.0, 345.0, 75.0, 105.0, 195.0, 225.0]
stroke: [520.0, 920.0]
plate:
  mass: 12.0
  com: [0.0, 0.0, 10.0]
  inertia: [400000.0, 410000.0, 790000.0, 0.0, 0.0, 0.0]
legs:
  cylinder_mass: 2.0
  piston_mass: 1.0
  max_force: 5000.0
  stiffness: 2000.0
"""


@pytest.fixture(scope="module")
def own_yaml(tmp_path_factory):
    path = tmp_path_factory.mktemp("platform") / "mine.yaml"
    path.write_text(OWN_YAML)
    return str(path)


@pytest.fixture(params=["utn-dynamic", "own"])
def platform_arg(request, own_yaml):
    """The ``--platform`` value: a preset, or the test's own YAML file."""
    return own_yaml if request.param == "own" else request.param


def cli_json(capsys, *argv) -> tuple[int, dict]:
    rc = main(list(argv))
    out = capsys.readouterr().out
    return rc, json.loads(out)


def assert_same(api, cli, path="") -> None:
    """Equal structure; numbers within RTOL/ATOL, everything else equal."""
    if isinstance(api, dict):
        assert isinstance(cli, dict) and set(api) == set(cli), f"{path}: keys {set(api) ^ set(cli)}"
        for k in api:
            assert_same(api[k], cli[k], f"{path}.{k}")
    elif isinstance(api, (list, tuple, np.ndarray)):
        assert len(api) == len(cli), f"{path}: lengths {len(api)} != {len(cli)}"
        for i, (a, c) in enumerate(zip(api, cli)):
            assert_same(a, c, f"{path}[{i}]")
    elif isinstance(api, bool) or api is None or isinstance(api, str):
        assert api == cli, f"{path}: {api!r} != {cli!r}"
    else:
        assert math.isclose(api, cli, rel_tol=RTOL, abs_tol=ATOL), f"{path}: {api!r} != {cli!r}"


def pose_mm_deg(q) -> list:
    q = np.asarray(q, dtype=float)
    return [*(q[:3] * MM), *(q[3:] * DEG)]


def home_offset(p, dx_mm=20.0, dy_mm=-10.0, angles_deg=(3.0, -2.0, 4.0)) -> list:
    """A pose near home in mm/deg, as typed on the command line."""
    return [dx_mm, dy_mm, p.home_height * MM + 15.0, *angles_deg]


def si(pose_cli) -> np.ndarray:
    """The typed pose in SI: × 1e-3 and × π/180, the products the unit factors define (the same operation as
    the CLI's, so the inputs agree bit for bit: a homotopy certificate's radius amplifies a one-ulp change)."""
    return np.r_[np.asarray(pose_cli[:3]) * 1e-3, np.asarray(pose_cli[3:]) * (math.pi / 180)]


def test_ik(capsys, platform_arg):
    p = sd.load_platform(platform_arg)
    typed = home_offset(p)
    rc, cli = cli_json(capsys, "ik", "--platform", platform_arg, "--pose", *map(str, typed), "--length-unit", "mm", "--angle-unit", "deg", "--json")  # fmt: skip
    api = sd.ik(p, si(typed)).to_dict()
    api.update(pose=typed, lengths=[v * MM for v in api["lengths"]], length_unit="mm", angle_unit="deg")
    assert_same(api, cli)
    assert rc == (0 if cli["within_stroke"] and cli["above_base"] else 1)


def test_ik_violations(capsys, platform_arg):
    """An unreachable pose: the violations (lengths, limits, excess) agree in mm."""
    p = sd.load_platform(platform_arg)
    typed = [0.0, 0.0, 1500.0, 0.0, 0.0, 0.0]
    rc, cli = cli_json(capsys, "ik", "--platform", platform_arg, "--pose", *map(str, typed), "--json")
    api = sd.ik(p, si(typed)).to_dict()
    assert api["violations"], "the pose should be out of stroke"
    api.update(pose=typed, lengths=[v * MM for v in api["lengths"]], length_unit="mm", angle_unit="deg")
    for v in api["violations"]:
        v.update(length=v["length"] * MM, limit=v["limit"] * MM, excess=v["excess"] * MM)
    assert_same(api, cli)
    assert rc == 1


@pytest.mark.parametrize("all_modes", [False, True])
def test_fk(capsys, platform_arg, all_modes):
    p = sd.load_platform(platform_arg)
    L = sd.ik(p, si(home_offset(p))).lengths
    typed = [f"{v * MM:.6f}" for v in L]
    rc, cli = cli_json(capsys, "fk", "--platform", platform_arg, "--lengths", *typed, *(["--all"] if all_modes else []), "--json")  # fmt: skip
    r = sd.fk(p, np.array([float(v) for v in typed]) * 1e-3, all_modes=all_modes)
    api = r.to_dict()
    api.update(lengths=[float(v) for v in typed], length_unit="mm", angle_unit="deg")
    for s in api["solutions"]:
        s.update(pose=pose_mm_deg(s["pose"]), residual=s["residual"] * MM)
        if "position_bound" in s:
            s.update(position_bound=s["position_bound"] * MM, angle_bound=s["angle_bound"] * DEG)
        if "uniqueness_radius_initial" in s:
            s["uniqueness_radius_initial"] *= MM
    assert_same(api, cli)
    assert rc == (0 if r.ok else 1)


@pytest.mark.parametrize("legs", [False, True])
def test_inverse_dynamics(capsys, platform_arg, legs):
    p = sd.load_platform(platform_arg)
    rc, cli = cli_json(capsys, "dynamics", "--platform", platform_arg, "--trajectory", "seed", "--legs", "on" if legs else "off", "--allow-out-of-stroke", "--json")  # fmt: skip
    api = sd.inverse_dynamics(p, "seed", legs=legs, allow_out_of_stroke=True).to_dict()
    assert_same(api, cli)
    assert rc == 0


def test_stiffness(capsys, platform_arg):
    p = sd.load_platform(platform_arg)
    typed = home_offset(p)
    rc, cli = cli_json(capsys, "stiffness", "--platform", platform_arg, "--pose", *map(str, typed), "--leg-stiffness", "3e6", "--payload", "3", "--payload-com", "0", "0", "50", "--json")  # fmt: skip
    r = sd.stiffness(p, si(typed), 3e6, payload=3.0, payload_com=(0, 0, 0.05))
    api = r.to_dict()
    d = np.asarray(api["deflection"])
    api.update(pose=typed, length_unit="mm", angle_unit="deg", deflection_edge_units=[*(d[:3] * MM), *(d[3:] * DEG)])
    assert_same(api, cli)
    assert rc == 0 and r.matrix.shape == (6, 6)


def test_modes(capsys, platform_arg):
    p = sd.load_platform(platform_arg)
    typed = home_offset(p)
    rc, cli = cli_json(capsys, "modes", "--platform", platform_arg, "--pose", *map(str, typed), "--leg-stiffness", "3e6", "--legs", "on", "--json")  # fmt: skip
    r = sd.modes(p, si(typed), 3e6, legs=True)
    api = r.to_dict()
    api["pose"] = typed
    assert_same(api, cli)
    assert rc == 0 and np.all(np.diff(r.frequencies_hz) >= 0)


def test_size(capsys, platform_arg):
    p = sd.load_platform(platform_arg)
    rc, cli = cli_json(capsys, "size", "--platform", platform_arg, "--trajectory", "rotating", "--dt", "0.01", "--payload", "2", "--json")  # fmt: skip
    r = sd.size(p, "rotating", dt=0.01, payload=2.0)
    assert_same(r.to_dict(), cli)
    assert rc == (0 if r.ok else 1)


def test_workspace(capsys, platform_arg):
    p = sd.load_platform(platform_arg)
    rc, cli = cli_json(capsys, "workspace", "--platform", platform_arg, "--orientation", "5", "0", "10", "--resolution", "0.05", "--limits", "stroke,joints", "--json")  # fmt: skip
    r = sd.workspace(p, np.radians([5.0, 0.0, 10.0]), 0.05, "stroke,joints")
    assert_same(r.to_dict(), cli)
    assert rc == 0 and r.volume > 0


def test_simulate(capsys, platform_arg, tmp_path):
    """A short closed loop (the python engine: no compiler needed); the CLI's summary adds the files it wrote."""
    p = sd.load_platform(platform_arg)
    out = tmp_path / "sim"
    rc, cli = cli_json(capsys, "simulate", "--platform", platform_arg, "--trajectory", "seed", "--fit", "--duration", "0.05", "--engine", "python", "--no-progress", "--out", str(out))  # fmt: skip
    r = sd.simulate(p, "seed", duration=0.05, engine="python", fit=True)
    assert (
        cli.pop("files")
        and json.loads((out / "summary.json").read_text())["max_leg_error_mm"] == cli["max_leg_error_mm"]
    )
    api = r.to_dict()
    for d in (api, cli):  # measured wall time of each run: positive, not equal
        assert d.pop("wall_s") > 0 and d.pop("real_time_factor") > 0
    assert_same(api, cli)
    assert rc == (0 if r.ok else 1)
    frame = r.log.to_pandas()  # the log by name, as a table: one row per plant step
    assert r.log["lengths"].shape == (len(r.log.t), 6) and len(frame) == len(r.log.t)
    assert np.array_equal(frame["length_error_3"], r.log["length_error"][:, 2])
    fig = r.plot()
    assert len(fig.axes) == 2
    fig.clf()


def test_run_program(capsys, platform_arg, tmp_path):
    """``run``'s lengths and forces along a motion program agree with ik and inverse_dynamics on the
    program's trajectory (``Trajectory.from_program``)."""
    p = sd.load_platform(platform_arg)
    prog = tmp_path / "square.stw"
    prog.write_text(f"units mm, deg\nmover(0, 0, {p.home_height * MM:.3f}, 0, 0, 0) en 0.3\nmove(x = 20) in 0.3\nmove(y = 20, beta = 2) in 0.3\n")  # fmt: skip
    rc, cli = cli_json(capsys, "run", str(prog), "--platform", platform_arg, "--out", str(tmp_path / "run"), "--json")  # fmt: skip
    traj = sd.Trajectory.from_program(prog, p)
    L = sd.ik(p, traj.q).lengths
    F = sd.inverse_dynamics(p, traj).forces
    api = {
        "samples": len(traj.t),
        "duration_s": traj.duration,
        "length_min_mm": L.min(axis=0) * MM,
        "length_max_mm": L.max(axis=0) * MM,
        "max_abs_force_N": np.abs(F).max(axis=0),
        "lengths_mm": [
            L[np.flatnonzero(traj.segment == k)[-1]] * MM for k, s in enumerate(traj.segments) if s.kind == "move"
        ],  # fmt: skip
    }
    assert_same(api, {k: cli[k] for k in api if k != "lengths_mm"} | {"lengths_mm": [m["lengths_mm"] for m in cli["moves"]]})  # fmt: skip
    assert rc == 0


def test_montecarlo(capsys, tmp_path):
    """Two runs on the preset (each run is a closed loop; the YAML platform's runs are the simulate test's)."""
    args = ["--runs", "2", "--seed", "5", "--vary", "anchor=±0.5mm", "gain_scale=±10%", "--duration", "0.05"]
    rc, cli = cli_json(capsys, "montecarlo", "--platform", "utn-dynamic", *args, "--engine", "python", "--workers", "0", "--no-progress", "--out", str(tmp_path / "a"), "--json")  # fmt: skip
    r = sd.montecarlo(
        sd.load_platform("utn-dynamic"), "seed", out=tmp_path / "b", runs=2, seed=5,
        vary=["anchor=±0.5mm", "gain_scale=±10%"], duration=0.05, engine="python", workers=0,
    )  # fmt: skip
    api = r.to_dict()
    for d in (api, cli):  # wall times and the folder names differ by nature
        d.pop("files"), d.pop("run_wall_s"), d["metrics"].pop("wall_s", None)
    assert_same(api, cli)
    assert rc == (0 if r.ok else 1) and len(r.to_pandas()) == 2


def test_firmware_generate(capsys, platform_arg, tmp_path):
    p = sd.load_platform(platform_arg)
    rc, cli = cli_json(capsys, "firmware", "generate", "--platform", platform_arg, "--no-compile", "--out", str(tmp_path / "a"), "--json")  # fmt: skip
    # the files record the options they were generated with, the platform as the command line named it
    r = sd.firmware.generate(p, tmp_path / "b", compile=False, platform_source=platform_arg)
    api = r.to_dict()
    assert api.pop("out") != cli.pop("out")
    assert_same(api, cli)
    assert (tmp_path / "a" / "sd_firmware.c").read_text() == (tmp_path / "b" / "sd_firmware.c").read_text()
    assert rc == 0


def test_firmware_check(capsys, platform_arg, tmp_path):
    """The generated firmware checked against the emulation: the same comparison from both (and identical)."""
    p = sd.load_platform(platform_arg)
    fw = sd.firmware.generate(p, tmp_path / "fw", compile=False).files
    source = next(str(f) for f in fw if f.name == "sd_firmware.c")
    rc, cli = cli_json(capsys, "firmware", "check", source, "--platform", platform_arg, "--poses", "500", "--duration", "0.05", "--json")  # fmt: skip
    r = sd.firmware.check(source, p, poses=500, duration=0.05)
    assert_same(r.to_dict(), cli)
    assert r.identical and rc == 0
