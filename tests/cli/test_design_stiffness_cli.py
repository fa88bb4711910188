"""``modes --drake``: the analytic modes confirmed by the linearised Drake plant, through the CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from stewart_drake.cli import main


def test_cli_modes_drake_json(capsys):
    assert main(["modes", "--pose", "50", "-30", "720", "5", "-3", "10", "--drake", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    f = np.array(out["frequencies_hz"])
    assert np.all(np.diff(f) >= 0) and len(f) == 6
    assert max(out["drake"]["relative_difference"]) <= 1e-6 and min(out["drake"]["mac"]) >= 0.999
    assert out["controller"]["samples_per_lowest_period"] == pytest.approx(1000.0 / f[0])
