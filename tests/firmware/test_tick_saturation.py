"""The tick's certificate says a saturation when one may happen: within its bounds a word of the arithmetic that
may clamp makes ``saturation_possible`` true, in the tick's certificate, in ``firmware certify --tick``'s verdict
and its exit status (1); the integrator's and the command's rails are the law's limits, reported as rails."""

from __future__ import annotations

import json

import numpy as np

from stewart_drake.commands._certify import format_tick
from stewart_drake.control import ControllerConfig
from stewart_drake.control.gains import DIFF_SHIFT, FixedGains
from stewart_drake.core.geometry import load_preset
from stewart_drake.firmware.certify.tick import certify_tick
from stewart_drake.fixedpoint import q15
from tests.cli._inprocess import cli

HUGE = dict(max_error_m=1e3, max_speed_mps=1e3, max_feedforward_n=1e7)  # beyond every word of the tick
RAILS = {"integrator (Q31)", "command sum u32 (Q31)", "command (Q15)"}


def _config():
    return ControllerConfig.for_platform(load_preset("utn-kinematic"))


def test_default_bounds_saturate_only_the_rails():
    cert = certify_tick(_config(), 5e-3, 0.1, 0.0)
    assert not cert.saturation_possible
    assert {w.name for w in cert.words if w.rail} == RAILS
    assert cert.to_dict()["saturation_possible"] is False


def test_unbounded_inputs_say_saturation_possible():
    cert = certify_tick(_config(), **HUGE)
    assert cert.saturation_possible and cert.to_dict()["saturation_possible"] is True
    possible = {w.name for w in cert.words if w.saturation == "possible"}
    # a difference of 10^6 counts per tick fills its 16-bit word: the filters fed by it may clamp too
    assert {"error e (counts)", "measurement difference", "derivative filter", "set-point velocity filter"} <= possible


def test_a_filter_said_to_clamp_does_clamp():
    """The derivative filter at the bounds' ends: held at its low end, then fed the high end, its sub(d, f)
    is clamped by q15 itself (the emulation's own flag, not the certificate's arithmetic)."""
    config = _config()
    cert = certify_tick(config, **HUGE)
    filt = next(w for w in cert.words if w.name == "derivative filter")
    g = FixedGains.from_si(config.gains, config.timing)
    d_hi = int(q15.sat16(q15.sat16(q15.MAX16) << DIFF_SHIFT))
    with q15.SaturationCounter() as sat:
        q15.add(filt.min, q15.mult_r(g.alpha, q15.sub(np.int64(d_hi), filt.min)))
    assert filt.saturation == "possible" and sat.total > 0


def test_cli_certify_tick_exit_status(capsys):
    box = ["--box", "px=0..1", "py=0..1", "pz=150..151", "a=0..0.001", "b=0..0.001", "g=0..0.001"]
    argv = ["firmware", "certify", "--platform", "utn-kinematic", *box, "--tick"]
    rc, out, err = cli(capsys, *argv, "--json")
    d = json.loads(out)
    assert rc == 0 and d["saturation_possible"] is False and d["tick"]["saturation_possible"] is False, err
    rc, out, err = cli(
        capsys, *argv, "--tick-error", "1e6", "--tick-speed", "1000", "--tick-feedforward", "1e7", "--json"
    )
    d = json.loads(out)
    assert rc == 1 and d["saturation_possible"] is True and d["tick"]["saturation_possible"] is True, err
    lines = format_tick(certify_tick(_config(), **HUGE)).splitlines()
    assert lines[-1].startswith("SATURATION POSSIBLE in sd_tick's arithmetic within these bounds: error e (counts)")
    assert "command" not in lines[-1] and "integrator (Q31)" not in lines[-1]  # the rails are not in the verdict
    assert any(
        x.strip().startswith("command (Q15)") and x.endswith("possible (its rail: the law's limit)") for x in lines
    )
