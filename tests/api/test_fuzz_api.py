"""A fuzz of the public API: every callable name in ``sd.__all__`` called with one argument replaced by
something a caller might pass by mistake (NaN, infinities, huge and negative numbers, complex values, text,
``None``, arrays of any small shape and dtype, ragged lists) answers with a ``StewartError`` or a result whose
``to_dict()`` is plain JSON data without NaN (an infinity may be the answer: a singular pose's condition number),
never another exception; and no message names a command-line flag.

CI runs a few derandomised examples per call (``ci``); ``pytest -m fuzz`` runs ``STEWART_FUZZ_EXAMPLES``.
``simulate``, ``montecarlo``, ``report``, ``optimize`` and the firmware names take seconds to minutes per good
call: they get only arguments their checks refuse before any work (``FAST_INVALID``)."""

from __future__ import annotations

import json
import math
import os
import warnings

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import stewart_drake as sd
from tests.cli._fuzz import ROOT, ci, fuzz

P = sd.load_platform("utn-dynamic")
HOME = P.home_pose()
POSE = np.array([0.01, -0.02, HOME[2] + 0.01, 0.02, -0.01, 0.03])
LENGTHS = sd.ik(P, POSE).lengths
PLATE = {"name": "fuzz", "mass": 2.0, "com": (0.0, 0.0, 0.01), "inertia": np.diag([0.02, 0.02, 0.04])}

# The calls: name -> (callable, its good arguments as keyword arguments). One is replaced per example.
CALLS = {
    "load_platform": (sd.load_platform, {"name_or_path": "utn-dynamic"}),
    "ik": (sd.ik, {"platform": P, "poses": POSE, "convention": "utn"}),
    "fk": (
        sd.fk,
        {
            "platform": P,
            "lengths": LENGTHS,
            "all_modes": False,
            "initial": None,
            "convention": "utn",
            "method": "homotopy",
            "tol": 1e-13,
            "max_iter": 30,
            "seed": 0,
        },
    ),
    "RealtimeFK": (
        sd.RealtimeFK,
        {"platform": P, "convention": "utn", "tol": 1e-13, "max_iter": 30, "max_substeps": 0, "engine": "numpy"},
    ),
    "RealtimeFK.solve_batch": (
        lambda lengths, previous: sd.RealtimeFK(P, engine="numpy").solve_batch(lengths, previous),
        {"lengths": LENGTHS, "previous": HOME},
    ),
    "inverse_dynamics": (
        sd.inverse_dynamics,
        {
            "platform": P,
            "trajectory": "seed",
            "legs": False,
            "coriolis": True,
            "gravity": 9.81,
            "t_end": None,
            "dt": 0.1,
            "convention": "utn",
            "length_unit": "m",
            "angle_unit": "rad",
            "allow_out_of_stroke": False,
            "smooth": None,
        },
    ),
    "stiffness": (
        sd.stiffness,
        {
            "platform": P,
            "pose": POSE,
            "leg_stiffness": 1e6,
            "convention": "utn",
            "legs": False,
            "payload": 1.0,
            "payload_com": (0.0, 0.0, 0.01),
            "gravity": 9.81,
        },
    ),
    "modes": (
        sd.modes,
        {
            "platform": P,
            "pose": POSE,
            "leg_stiffness": 1e6,
            "leg_damping": 10.0,
            "convention": "utn",
            "legs": False,
            "payload": 1.0,
            "payload_com": (0.0, 0.0, 0.01),
            "gravity": 9.81,
            "sample_rate": 1000.0,
            "drake": False,
        },
    ),
    "size": (
        sd.size,
        {
            "platform": P,
            "trajectory": "seed",
            "legs": False,
            "payload": 0.0,
            "payload_com": (0.0, 0.0, 0.0),
            "gravity": 9.81,
            "t_end": 1.0,
            "dt": 0.01,
            "convention": "utn",
            "length_unit": "m",
            "angle_unit": "rad",
        },
    ),
    "workspace": (
        sd.workspace,
        {
            "platform": P,
            "orientation": (0.0, 0.0, 0.0),
            "resolution": 0.05,
            "limits": "stroke",
            "convention": "utn",
            "joint_cone": 0.7,
            "max_condition": 100.0,
            "centre": None,
            "workers": 1,
        },
    ),
    "dsp_ik": (sd.dsp_ik, {"pose": [0.0, 0.0, 0.7, 0.0, 0.0, 0.0], "engine": "python", "trace": False}),
    "servo": (sd.servo, {"pose": [0.0, 0.0, 0.0, 0.0, 0.0, 0.0], "from_home": True, "trim": None}),
    "leg_fk": (sd.leg_fk, {"q1": 0.3, "q2": -0.6, "l1": None, "l2": None, "l3": None}),
    "leg_ik": (sd.leg_ik, {"px": 0.1, "py": -0.05, "gamma": None, "branch": "both"}),
    "Platform.utn": (sd.Platform.utn, {"b": 0.9, "d": 0.2, "a": 0.6, "stroke": (0.6, 1.0), **PLATE}),
    "Platform.radial": (
        sd.Platform.radial,
        {
            "base_radius": 0.5,
            "base_angles": np.radians([-10, 10, 110, 130, 230, 250]),
            "top_radius": 0.3,
            "top_angles": np.radians([-50, 50, 70, 170, 190, 290]),
            "stroke": (0.5, 0.9),
            **PLATE,
        },
    ),
    "Platform.replace": (
        P.replace,
        {"mass": P.mass, "com": P.com, "inertia": P.inertia, "home_height": P.home_height, "stroke": P.stroke},
    ),
    "Platform.from_anchors": (
        sd.Platform.from_anchors,
        {"base_anchors": P.base_anchors, "top_anchors_per_leg": P.top_anchors_per_leg, "stroke": P.stroke},
    ),
    "Trajectory.seed": (sd.Trajectory.seed, {"platform": P, "fit": False}),
    "Trajectory.rotating": (sd.Trajectory.rotating, {"platform": P, "fit": True}),
    "Trajectory.from_program": (
        sd.Trajectory.from_program,
        {"path": str(ROOT / "examples" / "circle.stw"), "platform": P, "rate": 50.0, "convention": "utn"},
    ),
    "inspect_model": (sd.inspect_model, {"platform": P}),  # write= would write into the working folder
    "viewer_readout": (sd.viewer_readout, {"platform": P, "pose": POSE, "convention": "utn", "modes": False}),
    "presets": (sd.presets, {}),
}

# The slow names: arguments their checks refuse before any work, each replaced by a value no call accepts.
FAST_INVALID = {
    "simulate": (sd.simulate, {"machine": P, "duration": 0.5, "period": 1e-3}),
    "montecarlo": (sd.montecarlo, {"machine": P, "runs": 2, "seed": 0}),
    "optimize": (sd.optimize, {"budget": 24, "seed": 0, "pop_size": 24}),
    "prove_workspace": (sd.prove_workspace, {"platform": P, "box_lo": [0, 0, 0.6], "box_hi": [0.01, 0.01, 0.61]}),
    "load_requirements": (sd.load_requirements, {"path": "no-such-requirements.yaml"}),
    "calibrate": (sd.calibrate, {"platform": P, "noise": (), "seed": 0}),
    "plan_measurements": (sd.plan_measurements, {"platform": P, "poses": 6, "candidates": 50, "targets": 3}),
    "simulate_measurements": (
        sd.simulate_measurements,
        {"platform": P, "poses": [[0, 0, 0.7, 0, 0, 0]] * 3, "seed": 0, "targets": 3, "noise": ()},
    ),
}
INVALID = st.sampled_from([None, "abc", math.nan, math.inf, -1, 1j, np.zeros((2, 3)), [math.nan] * 3, {"a": 1}])
FAST_FIXED = {  # the arguments each slow name needs besides the replaced one
    "montecarlo": {"out": "never-written"},
    "optimize": {"requirements": "no-such-requirements.yaml"},
    "calibrate": {"measurements": "no-such-measurements.csv"},
}

# Values a caller passes by mistake.
SCALARS = [None, "", "abc", "utn", True, math.nan, math.inf, -math.inf, -1, 0, 1e300, -1e300, 2**70, 1j, 1 + 2j]
BAD = st.one_of(
    st.sampled_from(SCALARS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(2**80), max_value=2**80),
    st.text(max_size=8),
    hnp.arrays(
        st.sampled_from([np.float64, np.float32, np.complex128, np.int64, np.bool_, np.uint8, "U3"]),
        hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=7),
    ),
    st.lists(st.one_of(st.floats(), st.text(max_size=2), st.none()), max_size=7),
    st.lists(st.lists(st.floats(), max_size=7), max_size=3),
    st.dictionaries(st.text(max_size=3), st.floats(), max_size=2),
)


@pytest.fixture(autouse=True, scope="module")
def scratch_folder(tmp_path_factory):
    """Every call runs in an empty scratch folder: a path argument drawn as text names nothing of the user's."""
    old = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("fuzz-api"))
    yield
    os.chdir(old)


def check_call(fn, kwargs: dict, value=None) -> None:
    """``fn(**kwargs)`` raises a ``StewartError`` with no ``--flag`` in it (beyond the ``value`` passed, which a
    message may echo), or returns a result whose ``to_dict()`` (where it has one) is JSON data without NaN."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", np.exceptions.ComplexWarning)  # a complex value cast silently
            result = fn(**kwargs)
    except sd.StewartError as e:
        text = str(e)
        if isinstance(value, str) and "--" in value:  # the user's own text, echoed
            text = text.replace(repr(value), "").replace(value, "")
        assert "--" not in text, f"the API names a command-line flag: {text}"
        return
    if hasattr(result, "to_dict"):
        d = result.to_dict()
        json.dumps(d)  # plain Python all the way down
        assert not any(isinstance(x, float) and math.isnan(x) for x in leaves(d)), d  # inf may be true: singular


def leaves(x):
    """The scalars of a ``to_dict()`` tree."""
    if isinstance(x, dict):
        for v in x.values():
            yield from leaves(v)
    elif isinstance(x, (list, tuple)):
        for v in x:
            yield from leaves(v)
    else:
        yield x


def replaced(data, table):
    name = data.draw(st.sampled_from(sorted(table)), label="call")
    fn, good = table[name]
    kwargs, value = dict(good), None
    if kwargs:
        arg = data.draw(st.sampled_from(sorted(kwargs)), label="argument")
        kwargs[arg] = value = data.draw(BAD, label="value")
    return fn, kwargs, value


@pytest.mark.parametrize("name", sorted(CALLS))
def test_good_arguments_give_results(name):
    """The baseline of every call is a result (so that a refusal in the fuzz is the replaced argument's)."""
    fn, kwargs = CALLS[name]
    check_call(fn, kwargs)


@ci(150)
@given(st.data())
def test_api_answers_bad_arguments_with_a_stewart_error(data):
    check_call(*replaced(data, CALLS))


# Values that are not a mistake for a slow name: ``None`` keeps the machine's own value in ``sd.simulate``.
VALID_FOR = {"simulate": {"duration": (None,), "period": (None,)}}


@pytest.mark.parametrize("name", sorted(FAST_INVALID))
@ci(12)
@given(st.data())
def test_slow_names_refuse_bad_arguments_before_work(name, data):
    fn, good = FAST_INVALID[name]
    kwargs = dict(good, **FAST_FIXED.get(name, {}))
    arg = data.draw(st.sampled_from(sorted(good)), label="argument")
    value = data.draw(INVALID, label="value")
    assume(not any(value is v for v in VALID_FOR.get(name, {}).get(arg, ())))
    kwargs[arg] = value
    with pytest.raises(sd.StewartError) as e:
        fn(**kwargs)
    assert "--" not in str(e.value), f"the API names a command-line flag: {e.value}"


@fuzz
@given(st.data())
def test_fuzz_api(data):
    check_call(*replaced(data, CALLS))
