"""Values echoed in messages are shortened the same way everywhere; gains that cannot be words say why
(issue 24, item 10)."""

import pytest

from stewart_drake.cli import main
from stewart_drake.control import DspTiming, PidGains
from stewart_drake.control.gains import FixedGains
from stewart_drake.errors import GainError, short_number, short_text


def test_short_number_and_text():
    assert short_number(1316.5554) == "1316.555" and short_number(1e300) == "1e+300"
    assert short_text("x" * 100) == "x" * 59 + "…" and short_text("abc") == "abc"


def test_fk_does_not_echo_a_300_digit_length(capsys):
    rc = main(["fk", "--lengths", "1e300", "1", "1", "1", "1", "1"])
    err = capsys.readouterr().err
    assert rc in (1, 2) and "1e+300" in err and len(err) < 400


def test_tiny_command_range_names_the_gain_and_max_force():
    """legs.max_force 1e-300 N: kp in the firmware's units is infinite (an OverflowError before)."""
    with pytest.raises(GainError, match=r"the kp gain .* command range of 1e-300 N \(legs.max_force\)"):
        FixedGains.from_si(PidGains(kp=1000.0, ki=0.0, kd=10.0, kv=10.0), DspTiming(command_range=1e-300))
