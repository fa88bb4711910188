"""The shared argument checks: the first offending index agrees with numpy's own ``argwhere``, shapes
are reported scipy-style, and a non-finite sample is named by its batch index counted from 1."""

import re

import numpy as np
import pytest

from stewart_drake.core.argcheck import (
    as_choice,
    as_flag,
    as_int,
    as_poses,
    as_real,
    as_real_array,
    check_finite_samples,
    check_shape,
    cli_names,
    first_index,
    param,
    setting,
    switch,
)
from stewart_drake.errors import NOT_FINITE_SAMPLE, SHAPE, ArgumentError, NotFiniteError, ShapeError, StewartError


@pytest.mark.parametrize("shape", [(), (7,), (3, 4), (2, 3, 5)])
def test_first_index_is_argwhere_first_row(shape):
    rng = np.random.default_rng(0)
    for _ in range(20):
        mask = rng.random(shape) < 0.2
        expected = tuple(int(i) for i in np.argwhere(mask)[0]) if mask.any() else None
        assert first_index(mask) == expected


def test_check_shape_messages():
    with pytest.raises(ShapeError, match=re.escape("Expected poses to have shape (..., 6), got (5,)")):
        check_shape(np.zeros(5), "poses", (..., 6))
    with pytest.raises(ShapeError, match=re.escape(SHAPE.format(name="anchors", shape="(6, 3)", got="(5, 3)"))):
        check_shape(np.zeros((5, 3)), "anchors", (6, 3))
    with pytest.raises(ShapeError, match=re.escape(SHAPE.format(name="v", shape="(..., 6, 3)", got="(3,)"))):
        check_shape(np.zeros(3), "v", (..., 6, 3))  # fewer dimensions than the trailing shape
    assert check_shape([[1, 2, 3]] * 6, "anchors", (6, 3)).dtype == float
    assert check_shape(np.zeros((2, 4, 6, 3)), "v", (..., 6, 3)).shape == (2, 4, 6, 3)


def test_non_finite_sample_is_named_counted_from_one():
    q = np.zeros((2, 3, 6))
    q[1, 2, 4] = np.inf
    message = NOT_FINITE_SAMPLE.format(what="pose", index="2,3", values=q[1, 2].tolist())
    with pytest.raises(NotFiniteError, match=re.escape(message)):
        as_poses(q)
    with pytest.raises(NotFiniteError, match=re.escape("x 4 is not finite: nan")):
        check_finite_samples([0.0, 1.0, 2.0, np.nan], "x", sample_ndim=0)
    single = np.r_[0.0, 0.0, np.nan, 0.0, 0.0, 0.0]
    with pytest.raises(NotFiniteError, match=re.escape("pose 1 is not finite")):
        as_poses(single)
    assert issubclass(NotFiniteError, StewartError) and issubclass(ShapeError, ValueError)


@pytest.mark.parametrize(
    "value",
    ["1.0", b"1", None, [1, "a"], [[1, 2], [3]], {"a": 1}, np.array(["a"]), 1j, np.array([1.0, 2j]), object()],
)
def test_as_real_array_refuses_what_is_not_real_numbers(value):
    """Text, None, ragged or mixed lists and complex values (never cast, imaginary part dropped) are refused."""
    with pytest.raises(ArgumentError, match=r"^Expected x to be real numbers, got "):
        as_real_array(value, "x")


def test_as_real_array_takes_numbers_of_any_real_dtype():
    for value in ([1, 2], np.array([True, False]), np.arange(3, dtype=np.uint8), np.float32(2.5), [np.int64(3), 4.5]):
        a = as_real_array(value, "x")
        assert a.dtype == np.float64 and np.array_equal(a, np.asarray(value, dtype=float))


def test_scalars_whole_numbers_choices_and_flags():
    class Typed(float):  # the command line's numbers print as the user typed them
        def __str__(self):
            return "1e-3"

    assert str(as_real(Typed(0.001), "x")) == "1e-3"
    assert as_real(2**70, "x") == 2.0**70 and as_real(10**400, "x") == np.inf  # beyond int64 and the floats
    for bad in (True, "1", None, [1.0], 1j):
        with pytest.raises(ArgumentError, match="^Expected x to be (one real number|real numbers, got complex)"):
            as_real(bad, "x")
    assert as_int(np.int64(3), "n", 1) == 3 and as_int(4.0, "n", 1, 5) == 4
    for bad, bounds in ((2.5, " in 1..5"), (True, " in 1..5"), (0, " in 1..5"), (6, " in 1..5"), (np.nan, " in 1..5")):
        with pytest.raises(ArgumentError, match=re.escape(ArgumentError.NOT_INT.format(name="n", bounds=bounds, value=repr(bad)))):  # fmt: skip
            as_int(bad, "n", 1, 5)
    assert as_choice("a", "c", ("a", "b")) == "a"
    with pytest.raises(ArgumentError, match=re.escape("Expected c to be one of 'a', 'b', got ['a']")):
        as_choice(["a"], "c", ("a", "b"))
    assert as_flag(np.bool_(True), "f") is True
    with pytest.raises(ArgumentError, match=re.escape("Expected f to be True or False, got 'no'")):
        as_flag("no", "f")


def test_messages_name_the_parameter_and_the_command_line_its_flag():
    """``param``/``setting``/``switch`` speak Python outside ``cli_names`` and the command line's flags inside."""
    assert (param("max_iter"), setting("length_unit", "mm"), switch("allow_out_of_stroke")) == (
        "max_iter",
        "length_unit='mm'",
        "allow_out_of_stroke=True",
    )
    with cli_names({"all_modes": "--all"}):
        assert (param("max_iter"), param("all_modes"), setting("length_unit", "mm"), switch("fit")) == (
            "--max-iter",
            "--all",
            "--length-unit mm",
            "--fit",
        )
    assert param("max_iter") == "max_iter"
