"""The motion language (seed 004, part 3): the seed's example program and a program with loops, run
through the interpreter (quintic trajectory → IK → inverse dynamics) on the utn-kinematic platform."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import leg_lengths, leg_unit_vectors
from stewart_drake.core.rotations import pose_to_si
from stewart_drake.report import run_standalone
from stewart_drake.script import compile_program, evaluate
from stewart_drake.script.emit import emit_matlab

TITLE = "Motion language: the seed's program and loops"
ORDER = 80
COST = 0.7  # CPU seconds (full report, measured): the report's workers start the costliest first
PRESET_ONLY = "it runs the motion language's example programs, written for the presets' dimensions"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SEED_MATLAB = ["L = CinematicaInversa(100,120,300,25,10,0);", "T = DinamicaInversa(L)"]


def build(section) -> None:
    import matplotlib.pyplot as plt

    from stewart_drake.script.plots import plot_forces, plot_lengths

    platform = load_preset("utn-kinematic")
    rate = 50.0 if section.quick else 100.0
    section.text(
        "Programs in the motion language are parsed by a Lark LALR(1) grammar (stewart_drake/script/stewart.lark), "
        "checked, executed into rest-to-rest quintic segments between waypoints (so velocities and accelerations "
        f"exist), sampled at {rate:g} Hz, and fed to the closed-form IK (with the stroke check) and the inverse "
        "dynamics (complete model, massless legs). Platform utn-kinematic (stroke 300..700 mm, an assumption of "
        "the preset), starting from its home pose pz = 100 mm."
    )
    rows = []
    for name in ("seed_004.stw", "circle.stw"):
        text = (EXAMPLES / name).read_text(encoding="utf-8")
        _, motion = compile_program(text, name, platform)
        result = evaluate(platform, motion.trajectory(rate))
        traj = result.trajectory
        if name == "seed_004.stw":
            lines = emit_matlab(motion).splitlines()
            section.check(
                "seed program --emit matlab reproduces the seed's two Matlab lines (lines differing)",
                sum(a != b for a, b in zip(lines[1:], SEED_MATLAB)) + abs(len(lines) - 3),
                0,
            )
            ref = leg_lengths(platform, pose_to_si([100, 120, 300, 25, 10, 0], "mm", "deg"))
            section.check(
                "seed program: final leg lengths vs the closed-form IK of the seed's pose",
                np.abs(result.L[-1] - ref).max() * 1e3,
                1e-9,
                "mm",
            )
            margin = (platform.L_max - result.L.max()) * 1e3
            section.text(
                "The seed's program: x=100, y=120, z=300, alpha=25, beta=10, gama=0, mover(x,y,z,alpha,beta,gama), "
                "read in mm and degrees. `stewart-drake compile examples/seed_004.stw --emit matlab` prints "
                f"{' / '.join(SEED_MATLAB)}. The pose is within the preset's stroke: lengths "
                + ", ".join(f"{v:.2f}" for v in result.L[-1] * 1e3)
                + f" mm; leg 4 is the closest to its end, {margin:.2f} mm below 700 mm."
            )
        F = result.F
        rows.append(
            [
                name,
                len(traj.moves),
                f"{traj.duration:.2f}",
                f"{result.L.min() * 1e3:.1f}",
                f"{result.L.max() * 1e3:.1f}",
                "-" if F is None else f"{np.abs(F).max():.1f}",
            ]
        )
        fig, axes = plt.subplots(
            2 if F is not None else 1, 1, figsize=(8, 6.5 if F is not None else 3.6), sharex=True, squeeze=False
        )
        plot_lengths(result, platform.name, platform.stroke * 1e3, ax=axes[0, 0])
        if F is not None:
            plot_forces(result, ax=axes[1, 0])
        section.figure(
            fig, f"motion_{Path(name).stem}", f"{name}: leg lengths and leg forces along the program's trajectory"
        )
        if F is not None:
            # Statics at the final rest pose: the legs carry the weight.
            u = leg_unit_vectors(platform, traj.q[-1])
            total = (F[-1][:, None] * u).sum(axis=0)
            section.check(
                f"{name}: at rest, Σ F_i u_i equals the plate's weight (relative error)",
                np.abs(total - [0, 0, platform.mass * 9.81]).max() / (platform.mass * 9.81),
                1e-9,
            )
    section.table(
        ["program", "moves", "duration (s)", "min L (mm)", "max L (mm)", "max |F| (N)"],
        rows,
        caption="Programs run on utn-kinematic",
    )


def main(argv=None):
    return run_standalone(__file__, argv)


if __name__ == "__main__":
    raise SystemExit(main())
