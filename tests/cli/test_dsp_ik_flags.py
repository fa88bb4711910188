"""``dsp-ik`` is an emulator: it shows what the firmware computes, with a flag and exit 1 for a pose outside
limits, as ``ik`` does (issue 24, item 5)."""

import json

import numpy as np

from stewart_drake.cli import main
from stewart_drake.fixedpoint.tp17 import tp17_trace


def test_seed_table_row_below_the_base_is_shown_and_flagged(capsys):
    """The seed's own table row 0 0 130 0.15π: a plate anchor 9 mm below the base; exit 1 with the lengths
    (those of the emulation, computed independently here), not an error alone."""
    rc = main(["dsp-ik", "--pose", "0", "0", "130", "0.15", "0", "0", "--json"])
    out, err = capsys.readouterr()
    res = json.loads(out)
    assert rc == 1
    assert res["dsp_lengths_mm"] == tp17_trace(np.array([0, 0, 130, 0.15, 0, 0.0])).lengths.astype(int).tolist()
    assert res["flags"] and "below the base" in res["flags"][0] and "leg 5 is at z = -9.035 mm" in err


def test_random_poses_in_the_dsp_range_are_computed(capsys):
    """Poses anywhere in the DSP's range (16-bit mm, one turn): every one prints six lengths; exit 0 or 1
    (flagged), never 2."""
    rng = np.random.default_rng(24)
    for _ in range(12):
        pose = np.r_[rng.integers(-32768, 32768, 3), np.round(rng.uniform(-1, 1, 3), 3)]
        rc = main(["dsp-ik", "--pose", *map(str, pose), "--json"])
        out, err = capsys.readouterr()
        res = json.loads(out)
        assert rc == (1 if res["flags"] else 0) and len(res["dsp_lengths_mm"]) == 6, (pose, err)
