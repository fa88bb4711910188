"""A plate negligible against the legs it joins is refused (issue 24, item 3): ``plate_mass=1e-30`` ran and
was reported as "lost tracking". The bound (``sanity.MIN_PLATE_TO_LEGS``: the plate at least 1/1000 of the
legs' moving mass) comes from the plant's ball joints, near-rigid constraints whose compliance is set from
the mass they join: a joint opens by about K·m_legs·h²/m_plate. Checked here on Drake's own plant: at the
bound the joints stay closed to within a tenth of the 10 µm sensor count (where ``simulate`` starts to warn),
and a plate 100× lighter opens them ~100× wider (the 1/m law the bound rests on)."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("pydrake")

import stewart_drake as sd  # noqa: E402
from stewart_drake.api.simulation import plan_run, run_plan  # noqa: E402
from stewart_drake.cli import main  # noqa: E402
from stewart_drake.core.sanity import MIN_PLATE_TO_LEGS, legs_moving_mass, require_plant_plate  # noqa: E402
from stewart_drake.errors import GeometryError  # noqa: E402

SENSOR_COUNT_M = 1e-5  # simulate's default sensor resolution


def light(platform, mass):
    """``platform`` with its plate's mass set to ``mass`` kg (the inertia scaled alike, as --vary plate_mass)."""
    return platform.replace(mass=mass, inertia=platform.inertia * mass / platform.mass)


def gap(platform) -> float:
    """The largest ball-joint gap (m) of a 0.2 s float-controller run (the checks skipped: a light plate)."""
    return run_plan(plan_run(platform, controller="float", duration=0.2, checks=False)).summary["max_constraint_gap_m"]


def test_the_joints_stay_closed_at_the_bound_and_open_as_one_over_the_mass():
    p = sd.load_platform("utn-dynamic")
    m0 = MIN_PLATE_TO_LEGS * legs_moving_mass(p)
    assert m0 == pytest.approx(1e-3 * 6 * (0.2 + 0.1))  # the preset's cylinders and pistons
    at, below = gap(light(p, m0)), gap(light(p, m0 / 100))
    assert at < SENSOR_COUNT_M / 10, at
    assert 30 < below / at < 300, (at, below)  # ~100: the gap follows 1/m_plate (factor 3 for the baseline)


def test_the_bound_refuses_a_negligible_plate_and_names_the_field():
    p = sd.load_platform("utn-dynamic")
    m0 = MIN_PLATE_TO_LEGS * legs_moving_mass(p)
    require_plant_plate(light(p, m0), "simulate")  # at the bound: accepted
    for mass in (1e-30, 1e-8, m0 * 0.99):
        with pytest.raises(GeometryError, match=r"plate's mass .* \(plate\.mass.*below 0\.001 of the legs' moving"):
            require_plant_plate(light(p, mass), "simulate")
    for name in sd.presets():  # every preset's plate is far above it
        q = sd.load_platform(name)
        if hasattr(q, "legs"):
            require_plant_plate(q, "simulate")


def test_simulate_refuses_a_platform_file_with_a_negligible_plate(tmp_path, capsys):
    text = (Path(sd.__file__).parent / "presets" / "utn-dynamic.yaml").read_text()
    text = text.replace(
        "plate: {thickness: 0.01036, density: 7580.0}",
        "plate: {mass: 1.0e-30, com: [0, 0, 0], inertia: [1.0e-33, 1.0e-33, 2.0e-33, 0, 0, 0]}",
    )
    assert "mass: 1.0e-30" in text
    (tmp_path / "tiny.yaml").write_text(text)
    assert (
        main(["simulate", "--platform", str(tmp_path / "tiny.yaml"), "--no-progress", "--out", str(tmp_path / "o")])
        == 2
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "the plate's mass 1e-30 kg (plate.mass" in err[0] and "at least 0.0018 kg" in err[0], err
    assert not (tmp_path / "o").exists()
