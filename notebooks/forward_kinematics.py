# ---
# jupyter:
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Forward kinematics: every assembly mode
#
# Six leg lengths do not fix a Stewart platform's pose: a general 6-6 platform can be assembled in up to 40
# ways. `sd.fk(..., all_modes=True)` finds every one by a complete parameter homotopy (each real solution
# certified), nearest home first; without `all_modes` it is Newton's method from home, the one a controller
# would track. Here: the radial template's platform (`stewart-drake init --platform-template radial`) and
# the UTN 3-6 preset, each mode drawn.

# %%
# %matplotlib inline
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import stewart_drake as sd

WORK = tempfile.TemporaryDirectory(prefix="stewart-drake-fk-")  # removed by the last cell, or when the kernel ends
OUT = Path(WORK.name)  # everything this notebook writes goes here

# %% [markdown]
# The platform file comes from the command line's template, as a user starts one.

# %%
template = subprocess.run(
    [sys.executable, "-m", "stewart_drake", "init", "--platform-template", "radial"],
    capture_output=True,
    text=True,
    check=True,
).stdout
(OUT / "radial.yaml").write_text(template)
platform = sd.load_platform(OUT / "radial.yaml")
lengths = np.array([0.750, 0.750, 0.750, 0.780, 0.780, 0.780])  # m

newton = sd.fk(platform, lengths)
print("Newton from home:", np.round(newton.solutions[0].pose, 5))

modes = sd.fk(platform, lengths, all_modes=True)
print(f"complete: {modes.complete}; {len(modes.solutions)} real assembly modes")
for i, sol in enumerate(modes.solutions, 1):
    flags = "above base" if sol.above_base else "BELOW base"
    print(f"{i}: pose {np.round(sol.pose, 4)}  certified {sol.certified}, {flags}, within stroke {sol.within_stroke}")

# %% [markdown]
# Every mode reproduces the six lengths (an independent check: the inverse kinematics of each pose), and the
# Newton solution is one of them.

# %%
for sol in modes.solutions:
    assert np.allclose(sd.ik(platform, sol.pose).lengths, lengths, atol=1e-9)
assert min(np.linalg.norm(s.pose - newton.solutions[0].pose) for s in modes.solutions) < 1e-8

# %% [markdown]
# ## Every mode drawn
#
# Base anchors (black), plate anchors (coloured) and legs, in the base frame, for each assembly mode.


# %%
def rotation_utn(a, b, g):
    """R = Ry(b) Rx(a) Rz(g): the platform's `utn` convention (see the units page)."""
    ca, sa, cb, sb, cg, sg = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(g), np.sin(g)
    rx = np.array([[1, 0, 0], [0, ca, -sa], [0, sa, ca]])
    ry = np.array([[cb, 0, sb], [0, 1, 0], [-sb, 0, cb]])
    rz = np.array([[cg, -sg, 0], [sg, cg, 0], [0, 0, 1]])
    return ry @ rx @ rz


def draw(ax, platform, pose, title):
    base = platform.base_anchors
    top = platform.top_anchors_per_leg - platform.rotation_centre
    p_top = pose[:3] + top @ rotation_utn(*pose[3:]).T
    ax.plot(*np.vstack([base, base[:1]]).T, "k-")
    ax.plot(*np.vstack([p_top, p_top[:1]]).T, "-", color="tab:blue")
    for b, t in zip(base, p_top):
        ax.plot(*np.array([b, t]).T, color="tab:orange")
    ax.set_title(title, fontsize=8)
    ax.set_box_aspect((1, 1, 1))


def draw_modes(platform, result, lengths):
    n = len(result.solutions)
    cols = min(n, 4)
    fig = plt.figure(figsize=(3 * cols, 3 * ((n + cols - 1) // cols)))
    for i, sol in enumerate(result.solutions):
        ax = fig.add_subplot((n + cols - 1) // cols, cols, i + 1, projection="3d")
        where = "above" if sol.above_base else "below"
        draw(ax, platform, sol.pose, f"mode {i + 1} ({where} base)")
    fig.suptitle(f"{platform.name}: lengths {np.round(lengths * 1e3, 1).tolist()} mm")
    plt.show()


draw_modes(platform, modes, lengths)

# %% [markdown]
# ## A 3-6 platform
#
# The UTN platform's plate joints are shared by pairs of legs: at most 16 modes. Its lengths at a tilted pose:

# %%
utn = sd.load_platform("utn-dynamic")
pose = np.array([0.02, -0.01, 0.7, 0.05, -0.03, 0.1])
lengths_utn = sd.ik(utn, pose).lengths
modes_utn = sd.fk(utn, lengths_utn, all_modes=True)
print(f"complete: {modes_utn.complete}; {len(modes_utn.solutions)} real modes; nearest home first:")
print(np.round(modes_utn.solutions[0].pose, 6), "(the pose we started from:", pose, ")")
assert np.allclose(modes_utn.solutions[0].pose, pose, atol=1e-9)
draw_modes(utn, modes_utn, lengths_utn)

# %% [markdown]
# The notebook's temporary folder is removed.

# %%
WORK.cleanup()
