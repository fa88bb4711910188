"""CPU seconds of the kernels that the workspace, fixedpoint_error and forward_kinematics report sections spend
their own time in, each beside the former form it replaced (the tests' references, which pin the same bits),
interleaved in one process, best of ``--repeat``: on a loaded machine the ratios are the figures to read.

    PYTHONPATH=. python benchmarks/bench_section_kernels.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import stewart_drake.core.assembly_modes as am
import stewart_drake.workspace as ws
from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import condition_above, inverse_jacobian, leg_lengths, scaled_condition
from stewart_drake.core.sampling import random_poses
from stewart_drake.workspace import columns, slabs
from tests.core.test_forward import _dedupe_one_at_a_time
from tests.core.test_sampling import _random_poses_whole_rounds
from tests.workspace.test_columns import _column_lengths_one_array
from tests.workspace.test_stroke_window import _former_inside_block

GD = load_preset("gonzalez-dutra-2009")
UTN_K = load_preset("utn-kinematic")
UTN_D = load_preset("utn-dynamic")


def _modes(dedupe):
    """The forward_kinematics section's multi-start searches (utn-dynamic at home, gonzalez-dutra-2009 near home)."""
    am._dedupe = dedupe
    q = GD.home_pose() + [0.02, -0.01, 0.01, 0.1, -0.05, 0.2]
    am.assembly_modes(UTN_D, leg_lengths(UTN_D, UTN_D.home_pose()))
    am.assembly_modes(GD, leg_lengths(GD, q))


def _sweeps(kernel):
    """The workspace section's 10 mm sweeps with optional limits (dexterity, both leg diameters) and its 5 mm one."""
    slabs.inside_block = kernel
    slabs.AXIS_DISTANCES.clear()
    for lim in (ws.Limits(max_condition=3.0), ws.Limits(leg_diameter=0.10), ws.Limits(leg_diameter=0.145)):
        ws.constant_orientation_workspace(GD, resolution=0.01, limits=lim, refine=False)
    ws.constant_orientation_workspace(GD, resolution=0.005, refine=False)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    new_dedupe, new_block, new_columns = am._dedupe, slabs.inside_block, columns._column_lengths
    J = inverse_jacobian(GD, random_poses(GD, 50_000, seed=1))
    cases = {
        "assembly modes (dedupe)": (lambda: _modes(_dedupe_one_at_a_time), lambda: _modes(new_dedupe)),
        "random_poses 200k box (fixedpoint_error)": (
            lambda: _random_poses_whole_rounds(UTN_K, 200_000, 20, 0.1, np.radians(25)),
            lambda: random_poses(UTN_K, 200_000, 20, 0.1, np.radians(25)),
        ),
        "random_poses 20k workspace (forward_kinematics)": (
            lambda: _random_poses_whole_rounds(GD, 20_000, 2, region="workspace"),
            lambda: random_poses(GD, 20_000, 2, region="workspace"),
        ),
        "stroke columns 2 mm (workspace)": (
            lambda: (
                setattr(columns, "_column_lengths", _column_lengths_one_array),
                ws.stroke_volume_columns(GD, 0.002),
            ),
            lambda: (setattr(columns, "_column_lengths", new_columns), ws.stroke_volume_columns(GD, 0.002)),
        ),
        "kappa > 3 of 5e4 J (dexterity sweep)": (
            lambda: scaled_condition(GD, J) > 3.0,
            lambda: condition_above(GD, J, 3.0),
        ),
        "sweeps: dexterity, 2 diameters, 5 mm (workspace)": (
            lambda: _sweeps(_former_inside_block),
            lambda: _sweeps(new_block),
        ),
    }
    print(f"best of {args.repeat}, CPU seconds, interleaved (former, now)")
    for name, (old, new) in cases.items():
        best = [np.inf, np.inf]
        for _ in range(args.repeat):
            for k, f in enumerate((old, new)):
                t = time.process_time()
                f()
                best[k] = min(best[k], time.process_time() - t)
        print(f"{name:50s} former {best[0]:6.3f} s   now {best[1]:6.3f} s   now/former {best[1] / best[0]:.2f}")
    am._dedupe, slabs.inside_block, columns._column_lengths = new_dedupe, new_block, new_columns


if __name__ == "__main__":
    main()
