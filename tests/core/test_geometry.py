import re

import numpy as np
import pytest

from stewart_drake.core.geometry import (
    PRESETS,
    Platform,
    load_platform,
    load_preset,
    triangular_plate,
    utn_anchors,
)
from stewart_drake.errors import GeometryError


def _base_kwargs(**over):
    kw = dict(name="t", stroke=[0.5, 0.9], mass=1.0, com=[0, 0, 0], inertia=np.eye(3) * 0.01)
    kw.update(over)
    return kw


def test_utn_anchor_table_of_spec():
    b, d, a = 925.0, 150.0, 612.5
    base, top = utn_anchors(b, d, a)
    s = np.sqrt(3) / 6
    np.testing.assert_allclose(base[0], [s * (2 * b + d), d / 2, 0])
    np.testing.assert_allclose(base[3], [-s * (b + 2 * d), -b / 2, 0])
    np.testing.assert_allclose(top[1], [-np.sqrt(3) / 3 * a, 0, 0])
    # The top is equilateral with side a.
    np.testing.assert_allclose(np.linalg.norm(top - np.roll(top, 1, axis=0), axis=1), a)


def test_utn_hexagon_sides_are_b_and_d():
    b, d = 0.4, 0.1
    base, _ = utn_anchors(b, d, 0.2)
    sides = np.linalg.norm(base - np.roll(base, -1, axis=0), axis=1)  # B1B2, B2B3, ..., B6B1
    np.testing.assert_allclose(sides, [b, d, b, d, b, d], rtol=1e-12)


def test_presets_load_with_documented_values():
    kin = load_preset("utn-kinematic")
    assert kin.top_anchors.shape == (3, 3) and list(kin.leg_top) == [0, 0, 1, 1, 2, 2]
    np.testing.assert_allclose(np.linalg.norm(kin.top_anchors[0] - kin.top_anchors[1]), 0.6125)
    dyn = load_preset("utn-dynamic")
    # Seed 004: steel sheet 7580 kg/m³, 10.36 mm thick, triangle of side 0.2 m -> 1.36 kg.
    assert dyn.mass == pytest.approx(1.36, abs=0.005)
    gd = load_preset("gonzalez-dutra-2009")
    np.testing.assert_allclose(np.linalg.norm(gd.base_anchors, axis=1), 0.624850)
    np.testing.assert_allclose(gd.stroke, [0.55, 0.95])
    # Paper: all legs at 0.75 m puts the plate at Z = 0.644 m (anchors fitted to 0.7 mm).
    assert gd.home_height == pytest.approx(0.644, abs=1e-3)


def test_triangular_plate_against_point_quadrature():
    # Independent check: integrate over a fine grid of the prism (midpoint rule, error ~h²).
    a, t, rho = 0.2, 0.01036, 7580.0
    m, com, I = triangular_plate(a, t, rho)
    n = 600
    xs = np.linspace(-np.sqrt(3) / 3 * a, np.sqrt(3) / 6 * a, n + 1)
    xs = (xs[1:] + xs[:-1]) / 2
    dx = xs[1] - xs[0]
    X, Y = np.meshgrid(xs, np.linspace(-a / 2, a / 2, 2 * n + 1)[:-1] + a / (4 * n))
    dy = a / (2 * n)
    half = (X + np.sqrt(3) / 3 * a) / np.sqrt(3)  # half-width of the triangle at abscissa x
    inside = np.abs(Y) <= half
    zs = (np.arange(20) + 0.5) * t / 20
    dm = rho * dx * dy * t / 20
    x, y = X[inside][:, None], Y[inside][:, None]
    z = zs[None, :]
    mass = dm * x.size * zs.size
    zc = z - t / 2
    Ixx = dm * np.sum(y**2 + zc**2)
    Izz = dm * np.sum(np.broadcast_to(x**2 + y**2, (x.shape[0], zs.size)))
    assert mass == pytest.approx(m, rel=5e-3)
    assert Ixx == pytest.approx(I[0, 0], rel=1e-2)
    assert Izz == pytest.approx(I[2, 2], rel=1e-2)
    assert com[2] == pytest.approx(t / 2)


def test_yaml_round_trip_with_mm(tmp_path):
    f = tmp_path / "mine.yaml"
    f.write_text(
        "length_unit: mm\nutn: {b: 400, d: 100, a: 200}\nstroke: [550, 950]\nplate: {mass: 2.0, inertia: [0.01, 0.01, 0.02, 0, 0, 0]}\n"
    )
    p = load_platform(str(f))
    assert p.name == "mine"
    ref = Platform.utn(
        0.4, 0.1, 0.2, **_base_kwargs(stroke=[0.55, 0.95], mass=2.0, inertia=np.diag([0.01, 0.01, 0.02]))
    )
    np.testing.assert_allclose(p.base_anchors, ref.base_anchors)
    np.testing.assert_allclose(p.stroke, [0.55, 0.95])


def test_radial_constructor_and_explicit_anchors_agree():
    ang = np.radians([0, 60, 120, 180, 240, 300])
    p = Platform.radial(0.5, ang, 0.3, ang + 0.2, **_base_kwargs())
    q = Platform(base_anchors=p.base_anchors, top_anchors=p.top_anchors, leg_top=np.arange(6), **_base_kwargs())
    np.testing.assert_allclose(p.top_anchors_per_leg, q.top_anchors_per_leg)


def test_arrays_are_read_only():
    p = load_preset("utn-dynamic")
    with pytest.raises(ValueError):
        p.base_anchors[0, 0] = 1.0


@pytest.mark.parametrize(
    "change, message",
    [
        (
            dict(base_anchors=np.zeros((5, 3))),
            GeometryError.SHAPE.format(name="base_anchors", shape=(6, 3), got=(5, 3)),
        ),
        (
            dict(base_anchors=np.full((6, 3), np.nan)),
            GeometryError.NOT_FINITE.format(name="base_anchors", value=[[np.nan] * 3] * 6),
        ),
        (dict(stroke=[0.9, 0.5]), GeometryError.STROKE.format(lmin=0.9, lmax=0.5)),
        (dict(stroke=[0.5, 0.5]), GeometryError.STROKE.format(lmin=0.5, lmax=0.5)),
        (dict(mass=-1.0), GeometryError.MASS.format(value=-1.0)),
        (dict(leg_top=[0, 0, 1, 1, 2]), GeometryError.LEG_TOP.format(value=[0, 0, 1, 1, 2])),
        (dict(leg_top=[0, 0, 1, 1, 2, 7]), GeometryError.LEG_TOP_RANGE.format(leg=6, anchor=7, n=3, last=2)),
        (dict(leg_top=[0, 0, 1, 1, 1, 1]), GeometryError.LEG_TOP_UNUSED.format(anchor=2)),
        (dict(inertia=np.diag([1.0, 1.0, 3.0])), GeometryError.INERTIA_PHYSICAL.format(moments=[1.0, 1.0, 3.0])),
        (
            dict(inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]),
            GeometryError.INERTIA_SYMMETRIC.format(value=[[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        ),
        (dict(top_anchors=np.zeros((2, 3))), GeometryError.TOP_SHAPE.format(shape=(2, 3))),
    ],
)
def test_validation_messages(change, message):
    base, top = utn_anchors(0.4, 0.1, 0.2)
    kw = dict(base_anchors=base, top_anchors=top, leg_top=np.array([0, 0, 1, 1, 2, 2]), **_base_kwargs())
    kw.update(change)
    with pytest.raises(GeometryError, match=re.escape(message)):
        Platform(**kw)


def test_coincident_base_anchors_are_named():
    base, top = utn_anchors(0.4, 0.1, 0.2)
    base = base.copy()
    base[4] = base[1]
    with pytest.raises(GeometryError, match=r"base anchors 2 and 5 coincide"):
        Platform(base_anchors=base, top_anchors=top, leg_top=np.array([0, 0, 1, 1, 2, 2]), **_base_kwargs())


def test_bad_utn_dimension():
    with pytest.raises(GeometryError, match=re.escape(GeometryError.UTN_DIMENSION.format(name="d", value=-0.1))):
        Platform.utn(0.4, -0.1, 0.2, **_base_kwargs())


def test_yaml_errors(tmp_path):
    with pytest.raises(
        GeometryError, match=re.escape(GeometryError.UNKNOWN_PLATFORM.format(name="nope", presets=", ".join(PRESETS)))
    ):
        load_platform("nope")
    with pytest.raises(GeometryError, match="does not exist"):
        load_platform(str(tmp_path / "missing.yaml"))
    f = tmp_path / "two.yaml"
    f.write_text(
        "utn: {b: 0.4, d: 0.1, a: 0.2}\nradial: {base_radius: 1, base_angles_deg: [0,1,2,3,4,5], top_radius: 1, top_angles_deg: [0,1,2,3,4,5]}\nstroke: [0.5, 0.9]\n"
    )
    with pytest.raises(
        GeometryError, match=re.escape(GeometryError.ANCHOR_DESCRIPTIONS.format(name="two", given=["utn", "radial"]))
    ):
        load_platform(str(f))
    f.write_text("utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\nlength_unit: inch\n")
    with pytest.raises(GeometryError, match="length_unit: unknown length unit 'inch'"):
        load_platform(str(f))
    f.write_text("utn: {b: 0.4, d: 0.1, a: 0.2}\nstroke: [0.5, 0.9]\ncolour: red\n")
    with pytest.raises(GeometryError, match="colour"):
        load_platform(str(f))


def test_every_preset_is_listed():
    for name in PRESETS:
        assert load_preset(name).name == name
