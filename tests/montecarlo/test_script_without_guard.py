"""``sd.montecarlo`` on Dask from a user's script that has no ``if __name__ == "__main__":`` guard: the workers
do not import the script (it ran again in each and every worker failed to start), and a motion defined in
the script reaches them by value."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

SCRIPT = """
import numpy as np
import stewart_drake as sd

print("script body ran")
seed = sd.Trajectory.seed()


def lifted(t):
    return seed.pose(t) + np.array([0.0, 0.0, 2e-3, 0.0, 0.0, 0.0])


motion = sd.Trajectory("lifted", lifted, seed.duration)
p = sd.load_platform("utn-dynamic")
kw = dict(runs=2, vary="anchor=±0.5mm", duration=0.05, engine="python")
dask = sd.montecarlo(p, motion, out="w1", workers=1, **kw)
here = sd.montecarlo(p, motion, out="w0", workers=0, **kw)
same = [{k: v for k, v in r.items() if k != "wall_s"} for r in dask.rows] == [
    {k: v for k, v in r.items() if k != "wall_s"} for r in here.rows
]
print("same rows", same)
"""


def test_a_script_without_a_main_guard_runs_a_dask_study(tmp_path):
    script = tmp_path / "study.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run(
        [sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.count("script body ran") == 1  # the script ran once: in no worker
    assert "same rows True" in r.stdout
    assert "__main__" not in r.stderr and "Traceback" not in r.stderr
