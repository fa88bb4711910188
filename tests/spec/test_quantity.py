"""The one quantity grammar: every form through ``spec.quantity`` and through each of its callers (the
``--vary`` SPEC, the calibration ``--noise``, the certificate's ``--error-budget`` and ``--box``), which
must read a text to the same SI numbers."""

from __future__ import annotations

import math
from decimal import Decimal

import pytest

from stewart_drake.calibration.noise import parse_noise
from stewart_drake.core.geometry import load_preset
from stewart_drake.errors import CalibrationError, CertifyError, QuantityError, SpecError
from stewart_drake.firmware.certify.box import parse_box
from stewart_drake.firmware.certify.optimize import parse_budget
from stewart_drake.montecarlo.spec import parse_value
from stewart_drake.spec.quantity import parse_number, parse_quantity

# (text, dimension, SI value as the exact decimal it denotes)
NUMBERS = [
    ("0.5mm", "length", "0.0005"),
    ("30um", "length", "0.00003"),
    ("30µm", "length", "0.00003"),
    ("10um", "length", "0.00001"),
    ("1e-3", "length", "0.001"),
    ("2ms", "time", "0.002"),
    ("8Hz", "frequency", "8"),
    ("4kN", "force", "4000"),
    ("150kg", "mass", "150"),
    ("250g", "mass", "0.25"),
]


@pytest.mark.parametrize(("text", "dim", "exact"), NUMBERS)
def test_units_scale_exactly(text, dim, exact):
    # the nearest float to the decimal the text denotes: 10um is 1e-05, not 10 * 1e-06 (= 1.0000000000000001e-05)
    assert parse_number(text, dim, "x") == float(Decimal(exact))


def test_degrees_scale_by_pi_over_180():
    assert parse_number("45deg", "angle", "x") == 45 * math.pi / 180
    assert parse_number("0.5", "angle", "x") == 0.5  # a bare number is SI (radians)


FORMS = [
    ("±0.5mm", "plusminus", (0.0005,)),
    ("+-0.5mm", "plusminus", (0.0005,)),
    ("±20%", "relative", (0.2,)),
    ("1mm..3mm", "range", (0.001, 0.003)),
    ("1mm|2mm|5mm", "choice", (0.001, 0.002, 0.005)),
    ("1mm,2mm,0", "vector", (0.001, 0.002, 0.0)),
    ("7mm", "value", (0.007,)),
]


@pytest.mark.parametrize(("text", "kind", "values"), FORMS)
def test_every_form(text, kind, values):
    forms = ("value", "plusminus", "relative", "range", "choice", "vector")
    q = parse_quantity(text, "length", "anchor", forms=forms)
    assert (q.kind, q.values, q.text) == (kind, values, text)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("5 parsecs", QuantityError.NUMBER.format(where="plate.com", text="5 parsecs", allowed="m, mm, um, µm, nm")),
        ("3mm..1mm", QuantityError.RANGE_ORDER.format(where="plate.com", text="3mm..1mm")),
        ("±-1mm", QuantityError.HALF_WIDTH.format(where="plate.com", text="±-1mm")),
        ("±100%", QuantityError.PERCENT_RANGE.format(where="plate.com", text="±100%")),
        ("1e999mm", QuantityError.NOT_FINITE.format(where="plate.com", text="1e999mm")),
    ],
)
def test_errors_name_the_path_and_the_text(text, message):
    with pytest.raises(QuantityError) as e:
        parse_quantity(text, "length", "plate.com")
    assert str(e.value) == message


def test_a_form_not_allowed_is_named():
    with pytest.raises(QuantityError, match=r"^--x: '1\.\.2': a range A\.\.B is not allowed here$"):
        parse_quantity("1..2", "time", "--x", forms=("value",))


# ---- the four callers read the same numbers ----------------------------------------------------


@pytest.mark.parametrize(
    ("key", "text"),
    [
        ("sensor_resolution", "10um"),
        ("actuator_lag", "±0.5ms"),
        ("force_limit", "±10%"),
        ("sample_period", "0.5ms..2ms"),
        ("payload", "0kg|50kg|150kg"),
        ("plate_mass", "150kg"),
    ],
)
def test_vary_reads_what_the_grammar_reads(key, text):
    from stewart_drake.montecarlo.spec import KEYS

    q = parse_quantity(text, KEYS[key][0], key)
    assert parse_value(key, text).values == q.values


def test_vary_vector_reads_the_grammar_vector():
    q = parse_quantity("1mm,2mm,30um", "length", "payload_position", forms=("vector",))
    assert parse_value("payload_position", "1mm,2mm,30um").values == q.values == (0.001, 0.002, 0.00003)


def test_vary_message_names_the_key_of_a_bad_percentage():
    # the message names the key the percentage belongs to
    with pytest.raises(SpecError, match=r"^--vary: force_limit: cannot read '1x' as a number"):
        parse_value("force_limit", "±1x%")


def test_noise_reads_what_the_grammar_reads():
    n = parse_noise("length=10um position=0.01mm angle=0.05deg")
    assert n.length == parse_number("10um", "length", "x") == 1e-05
    assert n.position == parse_number("0.01mm", "length", "x")
    assert n.angle == parse_number("0.05deg", "angle", "x")
    with pytest.raises(CalibrationError, match=r"^noise: length=2parsecs: expected a number >= 0"):
        parse_noise("length=2parsecs")


def test_budget_reads_what_the_grammar_reads():
    for text in ("0.5mm", "500um", "0.0005m", "0.0005", "30µm"):
        assert parse_budget(text) == parse_number(text, "length", "x")
    with pytest.raises(CertifyError, match="^error_budget must be a positive length such as 0.5mm, got '-1mm'$"):
        parse_budget("-1mm")


def test_box_takes_bare_numbers_in_its_unit_and_numbers_with_units_as_written():
    p = load_preset("utn-dynamic")
    a = parse_box(["pz=120..250", "a=-0.05..0.05"], p, length_unit="mm", angle_unit="pi")
    b = parse_box(["pz=120mm..250mm", "a=-9deg..9deg"], p, length_unit="mm", angle_unit="pi")
    assert (a.lo[2], a.hi[2]) == (0.12, 0.25)
    assert (b.lo[2], b.hi[2]) == (0.12, 0.25)
    assert b.hi[3] == pytest.approx(a.hi[3], rel=1e-15)  # 9° = 0.05 π, one rounding apart
    with pytest.raises(CertifyError, match=r"LO and HI must be finite numbers with LO <= HI"):
        parse_box(["pz=250mm..120mm"], p)
    with pytest.raises(CertifyError, match=r"expected KEY=LO\.\.HI"):
        parse_box(["pz=a..b"], p)
