"""The API and the command line give the same numbers for the remaining commands with ``--json``: ``dsp-ik``
(more to come: each command's API function is called in SI, the CLI in its own units, and the API's numbers
converted here, independently of the CLI's code).

Tolerances: a number the CLI prints unrounded is the API's times 1e3 or π/180 once: a few ulps (1e-12
relative). ``dsp-ik`` rounds its float lengths and differences to 1e-4 mm, so those agree within half that,
5e-5 mm, plus the ulps.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import stewart_drake as sd
from stewart_drake.cli import main

RTOL = 1e-12
MM = 1e3


def cli_json(capsys, *argv) -> tuple[int, dict]:
    rc = main(list(argv))
    return rc, json.loads(capsys.readouterr().out)


# dsp-ik: one pose within the range, one whose plate dips below the base (flagged, exit 1); angles in pi
# fractions (the firmware's own unit) and in degrees.
DSP_CASES = [
    (
        ["10", "-5", "700", "0.05", "-0.02", "0.1"],
        "pi",
        (0.010, -0.005, 0.700, 0.05 * math.pi, -0.02 * math.pi, 0.1 * math.pi),
    ),
    (["-37.9", "12", "-40", "9", "-4.5", "30"], "deg", (-0.0379, 0.012, -0.040, *np.radians([9, -4.5, 30]))),
]


@pytest.mark.parametrize(("typed", "unit", "si"), DSP_CASES)
def test_dsp_ik_matches_cli(capsys, typed, unit, si):
    rc, cli = cli_json(capsys, "dsp-ik", "--pose", *typed, "--angle-unit", unit, "--json", "--trace")
    api = sd.dsp_ik(si, trace=True)
    assert rc == (0 if api.ok else 1)
    d = api.to_dict()
    pose = d["pose"]
    # the firmware's words are the same integers on both sides
    assert [cli["pose"][f"{k}_mm"] for k in ("px", "py", "pz")] == [round(pose[k] * MM) for k in ("px", "py", "pz")]
    assert cli["pose"]["px_mm"] == math.trunc(float(typed[0]))  # truncated toward zero, as the firmware stores it
    for k in ("alpha", "beta", "gamma"):
        assert math.isclose(cli["pose"][f"{k}_pi"], pose[k] / math.pi, rel_tol=RTOL)
    assert cli["pose"]["angle_words"] == pose["angle_words"]
    assert cli["dsp_lengths_mm"] == [round(v * MM) for v in d["dsp_lengths"]] == api.dsp_words.tolist()
    assert cli["trace"] == d["trace"]
    for key in ("float_lengths", "difference"):
        np.testing.assert_allclose(cli[f"{key}_mm"], np.array(d[key]) * MM, rtol=0, atol=5e-5 + 1e-9)
    for side in ("firmware", "float"):
        assert cli["geometry_mm"][side] == pytest.approx({k: v * MM for k, v in d["geometry"][side].items()}, rel=RTOL)
    assert (cli["engine"], cli["saturations"], cli["flags"]) == (d["engine"], d["saturations"], d["flags"])


def test_dsp_ik_case_below_base_is_flagged():
    """The second case is a pose whose plate dips below the base: flagged by both (so the exit-1 path is run)."""
    assert not sd.dsp_ik(DSP_CASES[1][2]).ok
    assert sd.dsp_ik(DSP_CASES[0][2]).ok


def test_dsp_ik_refuses_angle_beyond_half_turn():
    with pytest.raises(sd.StewartError, match="beyond ±180°"):
        sd.dsp_ik([0, 0, 0.7, 3.2, 0, 0])
