"""Property tests over Monte Carlo specs (issue 24, item 10 and the fuzz "Monte Carlo specs" class): any
``--vary`` text, as words or as a YAML file, either is refused with a ``StewartError`` (one line, exit 2 at the
CLI) or gives a study whose every draw passes ``simulate``'s checks; never another exception (ZeroDivisionError,
decimal.InvalidOperation, TypeError, OverflowError were found by hand)."""

from __future__ import annotations

import yaml
from hypothesis import given
from hypothesis import strategies as st

from stewart_drake.core.geometry import load_platform
from stewart_drake.errors import StewartError
from stewart_drake.montecarlo.scenario import Study
from stewart_drake.montecarlo.spec import KEYS, RENAMED, parse_spec
from stewart_drake.montecarlo.study import check_study
from tests.cli._fuzz import ci, fuzz

PLATFORM = load_platform("utn-dynamic")
NUMBERS = st.one_of(
    st.sampled_from(["0", "-0", "1", "-1", "1e999999999999999999", "1e-300", "1e300", "nan", "inf", ".5", "2e-3"]),
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e6, max_value=1e6).map(repr),
)
UNITS = st.sampled_from(["", "m", "mm", "um", "µm", "nm", "s", "ms", "us", "N", "kN", "kg", "g", "%", "furlong"])
SCALARS = st.builds(lambda n, u: n + u, NUMBERS, UNITS)
VALUES = st.one_of(
    SCALARS,
    st.builds(lambda s: "±" + s, SCALARS),
    st.builds(lambda s: "+-" + s, SCALARS),
    st.builds(lambda a, b: f"{a}..{b}", SCALARS, SCALARS),
    st.builds(lambda xs: "|".join(xs), st.lists(SCALARS, min_size=1, max_size=3)),
    st.builds(lambda xs: ",".join(xs), st.lists(SCALARS, min_size=1, max_size=4)),
    st.sampled_from(["sample", "computation", "none", "sample|none", "late", ""]),
    st.text(max_size=8),
)
KEY_NAMES = st.one_of(st.sampled_from(list(KEYS) + list(RENAMED)), st.text(max_size=6))


@st.composite
def specs(draw):
    """(form, spec): "words" with key=value words, or "yaml" with the text of a YAML file (keys that are
    lists or mappings, values that are lists included)."""
    pairs = draw(st.lists(st.tuples(KEY_NAMES, VALUES), min_size=1, max_size=4))
    if draw(st.booleans()):
        return "words", [f"{k}={v}" for k, v in pairs]
    lines = []
    for k, v in pairs:
        key = draw(st.sampled_from([k, f"[{k}, x]", f"{{{k}: 1}}"])) if k else "''"
        val = draw(st.sampled_from([repr(v), f"[{v!r}]", "{a: 1}"]))
        lines.append(f"{key}: {val}")
    return "yaml", "\n".join(lines) + "\n"


def check_spec(form, spec, tmp_path) -> None:
    if form == "yaml":
        f = tmp_path / "vary.yaml"
        f.write_text(spec)
        try:
            yaml.safe_load(spec)
        except yaml.YAMLError:
            pass
        words = [str(f)]
    else:
        words = spec
    try:
        study = Study(PLATFORM, parse_spec(words), seed=0, runs=2, duration=0.05)
        check_study(study)
    except StewartError as e:
        assert "\n" not in str(e).strip() or form == "yaml", str(e)


@ci(40)
@given(specs())
def test_vary_specs(tmp_path_factory, spec):
    check_spec(*spec, tmp_path_factory.mktemp("spec"))


@fuzz
@given(specs())
def test_vary_specs_fuzz(tmp_path_factory, spec):
    check_spec(*spec, tmp_path_factory.mktemp("spec"))
