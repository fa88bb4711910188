"""``--vary`` keys say what they vary (issue 24, item 2): ``plate_mass``/``plate_com`` change the plate's own mass
properties, ``payload``/``payload_position`` add a point mass as ``size --payload`` does; the old names are
refused with what they meant; every draw passes ``simulate``'s checks before any run starts; values and keys
that crashed the parser (issue 24, item 10) are one line naming them."""

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform
from stewart_drake.design.payload import with_payload
from stewart_drake.errors import SpecError, StudyError
from stewart_drake.montecarlo.scenario import Study, draw, plant_platform
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.montecarlo.study import run_study


@pytest.mark.parametrize("old, new", [("payload_mass", "plate_mass"), ("payload_com", "plate_com")])
def test_old_keys_are_refused_naming_what_they_meant(old, new):
    with pytest.raises(SpecError, match=rf"the key '{old}' is no longer read: it .*plate's own.*use {new}"):
        parse_spec([f"{old}=±1"])


def test_payload_is_added_to_the_plate_as_size_does():
    """The plant of a draw with payload=20kg at 0,0,50mm is the plate with that point mass merged
    (``with_payload``, the function ``size --payload`` uses), checked by hand: total mass, centre of mass."""
    p = load_platform("utn-dynamic")
    st = Study(p, parse_spec(["payload=20kg", "payload_position=0,0,50mm"]), seed=0, runs=1)
    _, d = draw(st, 0)
    assert d.plate_mass == p.mass and d.payload == 20.0
    np.testing.assert_array_equal(d.payload_position, [0.0, 0.0, 0.05])
    plant = plant_platform(p, d)
    assert plant.mass == pytest.approx(p.mass + 20.0, rel=1e-15)
    np.testing.assert_allclose(
        plant.com, (p.mass * p.com + 20.0 * np.array([0, 0, 0.05])) / (p.mass + 20.0), rtol=1e-14
    )
    ref = with_payload(p, 20.0, [0, 0, 0.05])
    np.testing.assert_allclose(plant.inertia, ref.inertia, rtol=1e-14)


def test_plate_mass_sets_the_plate_mass():
    p = load_platform("utn-dynamic")
    _, d = draw(Study(p, parse_spec(["plate_mass=3kg"]), seed=0, runs=1), 0)
    plant = plant_platform(p, d)
    assert plant.mass == 3.0 and d.payload == 0.0
    np.testing.assert_allclose(plant.inertia, p.inertia * 3.0 / p.mass, rtol=1e-14)


@pytest.mark.parametrize(
    "vary, reason",
    [
        ("plate_mass=0kg", r"no plate mass properties"),
        ("plate_mass=1e-30kg", r"plate's mass 1e-30 kg .*below 0\.001 of the legs' moving mass"),
        # found by the spec fuzz at 5000 examples: 1e121 ticks allocated ("Maximum allowed dimension exceeded")
        (
            "sample_period=2.9e-123",
            r"(?<!-)vary sample_period 2\.9e-123 s would need .* steps.*draw a longer sample_period",
        ),
        ("sample_period=-0.015625", r"(?<!-)vary sample_period must be a positive number of seconds, got -0\.015625"),
        ("payload=5kg payload_position=0,0,-10mm", r"payload\.position must be at z >= 0 \(on the plate\)"),
        ("gain_scale=1e9", r"too large for a Q15"),
        ("anchor=±100mm", r"leaves the stroke"),
    ],
)
def test_a_draw_simulate_would_refuse_stops_the_study_before_any_run(tmp_path, vary, reason):
    """Exit-2 error naming run 0, its seed and the drawn values; the output folder is not created (no run
    started: a massless plate used to run and be reported as lost tracking)."""
    st = Study(load_platform("utn-dynamic"), parse_spec(vary.split()), seed=0, runs=2, duration=0.05)
    out = tmp_path / "mc"
    with pytest.raises(
        StudyError, match=rf"^run 0 \(seed \d+\) draws a scenario simulate would refuse \(.+\): .*{reason}"
    ):
        run_study(st, out, workers=0, progress=False)
    assert not out.exists()


def test_sensor_resolution_zero_is_named_not_a_division_by_zero():
    st = Study(load_platform("utn-dynamic"), parse_spec(["sensor_resolution=0"]), seed=0, runs=1, duration=0.05)
    with pytest.raises(StudyError, match=r"sensor_resolution: 0 m does not divide"):
        run_study(st, None, workers=0, progress=False)


def test_huge_exponent_is_not_finite():
    """1e999999999999999999 overflows Decimal's context (decimal.InvalidOperation/Overflow before)."""
    with pytest.raises(SpecError, match=r"force_limit: '1e999999999999999999' is not finite"):
        parse_spec(["force_limit=1e999999999999999999"])


@pytest.mark.parametrize("text", ["[a, b]: 1\n", "? {a: 1}\n: 2\n"])
def test_yaml_key_that_is_not_a_name(tmp_path, text):
    f = tmp_path / "vary.yaml"
    f.write_text(text)
    with pytest.raises(SpecError, match=r"vary.yaml:1: a key must be a name"):
        parse_spec([str(f)])


def test_negative_gain_scale_names_no_internal_class(tmp_path, capsys):
    rc = main(
        [
            "montecarlo",
            "--runs",
            "1",
            "--duration",
            "0.05",
            "--vary",
            "gain_scale=-1",
            "--out",
            str(tmp_path / "m"),
            "--workers",
            "0",
            "--no-progress",
        ]
    )
    err = capsys.readouterr().err
    # the drawn value is checked as the machine checks its spec path (controller.gain_scale)
    assert rc == 2 and "PidGains" not in err and "controller.gain_scale must be > 0, got -1" in err


def test_a_metric_no_parameter_moved_has_no_sensitivity_and_no_warning():
    """force_limit=4kN..6kN on a platform that never reaches 4 kN: the leg error is the same in every run;
    scipy's ConstantInputWarning was printed among the study's output (found trying it by hand)."""
    import warnings

    from stewart_drake.montecarlo.summary import sensitivity

    rows = [{"run": i, "seed": i, "force_limit_N": 4000.0 + i, "max_leg_error_m": 1e-3} for i in range(4)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert sensitivity(rows) == []
