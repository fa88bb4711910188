"""The public API's trust: a loaded ``Platform`` cannot be changed behind its checks (frozen, read-only arrays,
validated when built in code as a file is), every wrong argument is a ``StewartError`` naming the parameter as the
API spells it (the command line names its flag instead), and ``optimize`` with every variable fixed evaluates that
one design."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main
from stewart_drake.errors import SHAPE, ArgumentError, GeometryError, ShapeError

ROOT = Path(__file__).resolve().parents[2]
P = sd.load_platform("utn-dynamic")
POSE = np.array([0.0, 0.0, 0.7, 0.0, 0.0, 0.0])


# ----------------------------------------------------------------------------------------------
# A frozen Platform.


def test_a_loaded_platform_cannot_be_changed_in_place():
    """Its legs are frozen (a negative leg mass set after load used to reach the sizing), its per-leg lists are
    tuples, and no stored array can be written or made writeable again."""
    p = sd.load_platform("utn-dynamic")
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.legs.cylinder_mass = -5.0
    assert isinstance(p.legs.length_offset, tuple) and isinstance(p.legs.length_gain, tuple)
    for name in ("base_anchors", "top_anchors", "leg_top", "stroke", "com", "inertia", "rotation_centre"):
        arr = getattr(p, name)
        with pytest.raises(ValueError, match="read-only"):
            arr[...] = 0
        with pytest.raises(ValueError, match="WRITEABLE"):
            arr.flags.writeable = True
    assert sd.load_platform("utn-dynamic").legs == p.legs  # nothing above changed it


@pytest.mark.parametrize(
    "field, value, rule",
    [
        ("cylinder_mass", -5.0, "a number >= 0 up to 10000"),
        ("piston_mass", 2e4, "a number >= 0 up to 10000"),
        ("max_force", float("nan"), "a positive number up to 1e+08"),
        ("cylinder_radius", -0.01, "a number >= 0"),
        ("stiffness", -1e6, "a positive number"),
    ],
)
def test_a_platform_built_in_code_is_checked_as_a_file_is(field, value, rule):
    """``replace`` and direct construction run the platform file's leg rules (PLATFORM_RULES: masses up to 1e4 kg,
    never negative (0: massless legs), forces in (0, 1e8] N, radii >= 0)."""
    legs = dataclasses.replace(P.legs, **{field: value})
    message = GeometryError.LEG_FIELD.format(name=field, rule=rule, value=value)
    with pytest.raises(GeometryError, match=re.escape(message)):
        P.replace(legs=legs)
    with pytest.raises(GeometryError, match=re.escape(message)):
        sd.Platform.utn(0.9, 0.2, 0.6, stroke=(0.6, 1.0), name="x", mass=1.0, com=np.zeros(3), inertia=np.eye(3) / 10, legs=legs)  # fmt: skip


def test_platform_fields_of_the_wrong_kind_are_refused():
    with pytest.raises(GeometryError, match=re.escape("Platform.name must be text, got 5")):
        P.replace(name=5)
    with pytest.raises(GeometryError, match=re.escape("Platform.legs must be a LegConfig, got {'cylinder_mass': 1}")):
        P.replace(legs={"cylinder_mass": 1})
    with pytest.raises(GeometryError, match=re.escape("mass must be numbers, got 'heavy'")):
        P.replace(mass="heavy")
    with pytest.raises(GeometryError, match="com must be numbers"):
        P.replace(com=[0, 0, 1j])


def test_a_replaced_platform_round_trips_through_its_file(tmp_path):
    """A platform with legs changed in code (checked) writes a file ``load_platform`` reads back to the same legs."""
    legs = dataclasses.replace(P.legs, cylinder_mass=0.7, length_offset=[0.001] * 6)
    p = P.replace(legs=legs)
    back = sd.load_platform(p.to_yaml(tmp_path / "p.yaml"))
    assert back.legs == p.legs and back.legs.length_offset == (0.001,) * 6


# ----------------------------------------------------------------------------------------------
# The API's arguments: a StewartError naming the parameter.


@pytest.mark.parametrize(
    "call, error, message",
    [
        (
            lambda: sd.fk(P, np.tile(sd.ik(P, POSE).lengths, (3, 1))),
            ShapeError,
            SHAPE.format(name="lengths", shape="(6,)", got="(3, 6)"),
        ),  # fmt: skip
        (
            lambda: sd.fk(P, sd.ik(P, POSE).lengths, seed=-1),
            ArgumentError,
            ArgumentError.NOT_INT.format(name="seed", bounds=f" in 0..{2**63 - 1}", value="-1"),
        ),  # fmt: skip
        (
            lambda: sd.fk(P, sd.ik(P, POSE).lengths, True, method="magic"),
            ArgumentError,
            ArgumentError.CHOICE.format(name="method", choices="'homotopy', 'multi-start'", value="'magic'"),
        ),  # fmt: skip
        (
            lambda: sd.fk(P, sd.ik(P, POSE).lengths, max_iter=2.5),
            ArgumentError,
            ArgumentError.NOT_INT.format(name="max_iter", bounds=" >= 1", value="2.5"),
        ),  # fmt: skip
        (
            lambda: sd.stiffness(P, np.tile(POSE, (3, 1)), 1e6),
            ShapeError,
            SHAPE.format(name="pose", shape="(6,)", got="(3, 6)"),
        ),  # fmt: skip
        (
            lambda: sd.stiffness(P, POSE, [1e6] * 5),
            ShapeError,
            SHAPE.format(name="leg_stiffness", shape="() or (6,)", got="(5,)"),
        ),  # fmt: skip
        (lambda: sd.ik(P, POSE + 1j), ArgumentError, "Expected poses to be real numbers, got complex values"),
        (
            lambda: sd.ik("utn-dynamic", POSE),
            ArgumentError,
            ArgumentError.NOT_PLATFORM.format(name="platform", value="'utn-dynamic'"),
        ),  # fmt: skip
        (
            lambda: sd.RealtimeFK("utn-dynamic"),
            ArgumentError,
            ArgumentError.NOT_PLATFORM.format(name="platform", value="'utn-dynamic'"),
        ),  # fmt: skip
        (
            lambda: sd.workspace(P, resolution="fine"),
            ArgumentError,
            ArgumentError.NOT_NUMBER.format(name="resolution", value="'fine'"),
        ),  # fmt: skip
        (
            lambda: sd.leg_ik(0.1, 0.0, branch="c"),
            ArgumentError,
            ArgumentError.CHOICE.format(name="branch", choices="'a', 'b', 'both'", value="'c'"),
        ),  # fmt: skip
        (
            lambda: sd.dsp_ik(POSE, trace="yes"),
            ArgumentError,
            ArgumentError.NOT_BOOL.format(name="trace", value="'yes'"),
        ),  # fmt: skip
    ],
)
def test_wrong_arguments_are_stewart_errors_naming_the_parameter(call, error, message):
    with pytest.raises(error, match=re.escape(message)):
        call()


def test_absurd_loads_are_refused_not_computed():
    """A 1e300 kg payload or 1e300 m/s² gravity gave a stiffness result with ``ok`` True (and ``size`` a
    non-finite RMS force): beyond 1000 t and ±100 m/s² (10 g) they are unit mistakes."""
    with pytest.raises(sd.StewartError, match=re.escape("payload: payload mass 1e+300 kg is beyond 1e+06 kg")):
        sd.stiffness(P, POSE, 1e6, payload=1e300)
    with pytest.raises(sd.StewartError, match=re.escape("gravity 1e+300 m/s² is beyond ±100 m/s²")):
        sd.size(P, "seed", gravity=1e300)


@pytest.mark.parametrize(
    "call, api, argv, cli",
    [
        (
            lambda: sd.fk(P, sd.ik(P, POSE).lengths, tol=-1.0),
            "tol must be a positive number of metres, got -1",
            ["fk", "--platform", "utn-dynamic", "--lengths", *["700"] * 6, "--length-unit", "mm", "--tol", "-1"],
            "--tol must be a positive number of metres, got -1",
        ),
        (
            lambda: sd.modes(P, POSE, 1e6, leg_damping=1e300),
            "leg_damping 1e+300 N·s/m gives damping ratios",
            [
                "modes",
                "--platform",
                "utn-dynamic",
                "--pose",
                "0",
                "0",
                "700",
                "0",
                "0",
                "0",
                "--leg-stiffness",
                "1e6",
                "--leg-damping",
                "1e300",
            ],  # fmt: skip
            "--leg-damping 1e+300 N·s/m gives damping ratios",
        ),
        (
            lambda: sd.ik(P, [0.0, 0.0, 700.0, 0.0, 0.0, 0.0]),
            "use length_unit='mm'",
            ["ik", "--platform", "utn-dynamic", "--pose", "0", "0", "700", "0", "0", "0", "--length-unit", "m"],
            "use --length-unit mm",
        ),
    ],
)
def test_api_messages_name_parameters_and_the_command_line_its_flags(call, api, argv, cli, capsys):
    """The same check speaks each side's language: ``tol`` to a Python caller, ``--tol`` on the command line."""
    with pytest.raises(sd.StewartError) as e:
        call()
    assert api in str(e.value) and "--" not in str(e.value)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert cli in err, err


# ----------------------------------------------------------------------------------------------
# optimize with every variable fixed.


def test_optimize_with_every_variable_fixed_evaluates_that_design(tmp_path):
    """low == high for every variable (the requirements file allows it) left pymoo no population to ask for and
    ``optimize`` raised AttributeError; now the search is that one design, evaluated once."""
    text = (ROOT / "examples" / "seed_001_requirements.yaml").read_text()
    fixed = {"base_radius": 0.5, "top_radius": 0.3, "base_half_angle": 10, "top_half_angle": 10, "home_height": 0.6}
    for name, value in fixed.items():
        text = re.sub(rf"(\n  {name}: )\[[^]]*\]", rf"\g<1>[{value}, {value}]", text)
    path = tmp_path / "fixed.yaml"
    path.write_text(text)
    r = sd.optimize(path, budget=24, pop_size=4).to_dict()
    assert r["search"]["designs"] == 1 and r["search"]["evaluated_now"] == 1
    assert r["variables"] == pytest.approx({**fixed, "base_half_angle": np.radians(10), "top_half_angle": np.radians(10)})  # fmt: skip


def test_simulate_measurements_names_its_own_option(tmp_path, capsys):
    """simulate-measurements' errors are drawn with the --vary grammar, but a bad one names --errors (it named
    --vary, an option the command does not have)."""
    from stewart_drake.cli import main

    poses = tmp_path / "p.csv"
    poses.write_text("px,py,pz,a,b,g\n0,0,700,0,0,0\n0,0,710,0,0,0\n")
    argv = ["simulate-measurements", "--platform", "utn-dynamic", "--poses", str(poses), "--out", str(tmp_path / "o")]
    assert main([*argv, "--errors", "anchor=abc"]) == 2
    err = capsys.readouterr().err
    assert "--errors: anchor" in err and "--vary" not in err
    with pytest.raises(sd.StewartError, match=r"^errors: anchor") as e:
        sd.simulate_measurements("utn-dynamic", [[0, 0, 0.7, 0, 0, 0]] * 3, errors=["anchor=abc"])
    assert "--" not in str(e.value)
