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
    pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    rc = main(["fk", "--lengths", "1e300", "1", "1", "1", "1", "1"])
    err = capsys.readouterr().err
    assert rc in (1, 2) and "1e+300" in err and len(err) < 400


def test_tiny_command_range_names_the_gain_and_max_force():
    """legs.max_force 1e-300 N: kp in the firmware's units is infinite (an OverflowError before)."""
    with pytest.raises(GainError, match=r"the kp gain .* command range of 1e-300 N \(legs.max_force\)"):
        FixedGains.from_si(PidGains(kp=1000.0, ki=0.0, kd=10.0, kv=10.0), DspTiming(command_range=1e-300))


def test_a_1e308_cell_names_the_column_and_samples(tmp_path, capsys):
    """A 1e308 cell is a number, but its rate overflows: scipy's "`dydx` must contain only finite values"
    before; now the file, column and samples."""
    pytest.importorskip("pydrake")  # runs a Drake-backed command; the numpy-layer run (no pydrake) skips it
    f = tmp_path / "big.csv"
    f.write_text(
        "t,px,py,pz,ax,ay,az\n" + "".join(f"{i * 0.1},0,0,{1e308 if i == 2 else 0.7},0,0,0\n" for i in range(5))
    )
    for cmd in (["dynamics"], ["size"], ["simulate", "--out", str(tmp_path / "o"), "--no-progress"]):
        assert main([*cmd[:1], "--trajectory", str(f), *cmd[1:]]) == 2
        err = capsys.readouterr().err
        assert "big.csv: column pz goes from 0.700000 to 1e+308 (SI) between t = 0.100000 and 0.200000 s" in err
        assert "dydx" not in err


def test_length_lsb_that_overflows_the_firmware_is_refused(tmp_path, capsys):
    """--length-lsb 1e10 made COUNTS_PER_LSB 1e15: gcc's -Werror=overflow on the generated C."""
    assert main(["firmware", "generate", "--length-lsb", "1e10", "--out", str(tmp_path / "fw")]) == 2
    err = capsys.readouterr().err
    assert "is 1e+15 sensor counts" in err and "16-bit error word" in err and "Werror" not in err
    assert not (tmp_path / "fw").exists()
