"""The generated module records its options and ``firmware check`` uses them (issue 24, item 7): a check
with another option than the generated one reported "500 differ ... DIFFERS" with no hint."""

import pytest

from stewart_drake.cli import main
from stewart_drake.firmware.fingerprint import read_fingerprint


@pytest.fixture(scope="module")
def module(tmp_path_factory):
    out = tmp_path_factory.mktemp("fw") / "fw"
    argv = ["firmware", "generate", "--platform", "utn-dynamic", "--length-lsb", "5e-4", "--rate", "500"]
    assert main([*argv, "--out", str(out), "--no-compile"]) == 0
    return out


def test_generated_files_record_their_options(module):
    for name in ("sd_firmware.c", "sd_firmware.h"):
        opts, where = read_fingerprint(module / name)
        assert where == module / name
        assert (opts["platform"], opts["length_lsb"], opts["rate"], opts["word_bits"]) == (
            "utn-dynamic",
            5e-4,
            500.0,
            16,
        )


def test_check_uses_the_recorded_options(module, capsys):
    """Without options the check emulates the recorded 0.5 mm LSB at 500 Hz: identical (it differed with the
    defaults, 1 mm at 1 kHz)."""
    rc = main(["firmware", "check", str(module / "sd_firmware.c"), "--poses", "2000", "--duration", "0.05"])
    out = capsys.readouterr().out
    assert rc == 0 and "identical to the emulation" in out


def test_check_names_a_differing_option(module, capsys):
    rc = main(["firmware", "check", str(module / "sd_firmware.c"), "--length-lsb", "0.001", "--poses", "100"])
    err = capsys.readouterr().err
    assert rc == 2 and "generated with other options (--length-lsb 0.001 here, 0.0005 in" in err
