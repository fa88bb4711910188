"""Property test: random token soup never makes the front end fail with anything but ScriptError."""

import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from stewart_drake.script import ScriptError, check, parse

TOKENS = [
    "x",
    "y",
    "z",
    "alpha",
    "gama",
    "i",
    "pi",
    "sin",
    "foo",
    "0",
    "1",
    "2.5",
    ".5",
    "1e3",
    "1e999",
    "=",
    ":=",
    "==",
    "#",
    "<>",
    "<",
    "<=",
    ">",
    ">=",
    "+",
    "-",
    "*",
    "/",
    "DIV",
    "MOD",
    "(",
    ")",
    ",",
    ";",
    "mover",
    "move",
    "en",
    "in",
    "wait",
    "units",
    "mm",
    "deg",
    "FOR",
    "TO",
    "BY",
    "DO",
    "END",
    "IF",
    "THEN",
    "ELSIF",
    "ELSE",
    "WHILE",
    "AND",
    "OR",
    "NOT",
    "LOOP",
    "// c\n",
    "(* c *)",
    "(*",
    "\n",
    "$",
    "@",
    '"',
    "é",
    "\t",
    "",
]


@settings(max_examples=400, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.one_of(st.sampled_from(TOKENS), st.text(max_size=3)), max_size=40), st.sampled_from([" ", ""]))
def test_token_soup_only_raises_script_errors(tokens, sep):
    text = sep.join(tokens)
    try:
        check(parse(text, "soup.stw"))
    except ScriptError as e:
        assert str(e).startswith("soup.stw:")


@settings(max_examples=50, deadline=None, derandomize=True)
@given(st.integers(min_value=1, max_value=400))
def test_deep_nesting_is_an_error_not_a_crash(depth):
    for text in (
        "x = " + "(" * depth + "1" + ")" * depth,
        "x = " + "-" * depth + "1",
        "x = " + "sin(" * depth + "1" + ")" * depth,
        "IF 1 < 2 THEN " * depth + "END " * depth,
    ):
        try:
            check(parse(text, "deep.stw"))
        except ScriptError as e:
            assert re.search(
                r"nested more than (100|60|16) levels deep", str(e)
            )  # expressions 100, statements 60, loops 16
