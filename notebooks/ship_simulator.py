# ---
# jupyter:
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # The ship simulator: motion cueing in sea states 3–6
#
# Seed 001's 6-6 platform (`gonzalez-dutra-2009`) is a ship-simulator motion base. What it is fed is not a pose
# trajectory but a ship's motion as the rider feels it: the specific force and angular velocity at the head
# (`sd.Drive`). `sd.cue` turns that into platform poses (classical washout, hand-set or tuned, or MPC), keeps them
# inside the workspace with the limit guard, and scores them by what a rider perceives (otolith and
# semicircular-canal models). With `simulate=True` the poses run through the machine's own fixed-point controller
# and the Drake plant, and the scores are those of the plant's motion. Drives are kept short (20 s) so that the
# notebook runs in seconds.

# %%
# %matplotlib inline
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

import stewart_drake as sd

WORK = tempfile.TemporaryDirectory(prefix="stewart-drake-cue-")  # removed by the last cell, or when the kernel ends
OUT = Path(WORK.name)  # everything this notebook writes goes here
machine = sd.load_machine("gonzalez-dutra-2009")
SECONDS = 20.0
drives = {s: sd.ship_drive(s, duration=SECONDS, seed=s) for s in (3, 4, 5, 6)}

# %% [markdown]
# ## The ship's motion
#
# Heave, surge and sway show up as specific force, roll and pitch as angular velocity; a rougher sea moves more.

# %%
fig, ax = plt.subplots(2, 1, figsize=(9, 5), sharex=True)
for s, drive in drives.items():
    ax[0].plot(drive.t, drive.specific_force[:, 2], lw=0.8, label=f"sea state {s}")
    ax[1].plot(drive.t, drive.angular_velocity[:, 0], lw=0.8)
ax[0].set(ylabel="f_z [m/s²]", title="the ship at the rider's head")
ax[1].set(xlabel="t [s]", ylabel="roll rate [rad/s]")
ax[0].legend(ncol=4, fontsize=8)
plt.show()

# %% [markdown]
# ## Hand-set classical washout, every sea state
#
# The limit guard scales a pose toward home along the whole pose (never one leg at a time), so no sample leaves
# the stroke; `limits` counts them by the exact IK, and the scores compare perceived motion.

# %%
runs = {s: sd.cue(machine, drive, algorithm="classical") for s, drive in drives.items()}


SHOWN = ("specific_force_rmse", "angular_velocity_rmse", "specific_force_pearson", "false_cue_share", "stroke_use_pct")


def row(scores: dict, limits: dict) -> dict:
    """One line of a side-by-side table: the main scores (all of them: `scores.keys()`) and the limit count."""
    return {**{k: scores[k] for k in SHOWN}, "outside stroke": limits["outside_stroke"]}


pd.DataFrame({f"sea state {s}": row(r.scores, r.limits) for s, r in runs.items()}).transpose()

# %% [markdown]
# ## Tuned against hand-set, and in the loop
#
# Sea state 5: the washout tuned for this drive, then both run through the fixed-point controller and the plant.

# %%
rough = drives[5]
compared = {
    algorithm: sd.cue(machine, rough, algorithm=algorithm, simulate=True) for algorithm in ("classical", "tuned")
}
for algorithm, r in compared.items():
    print(f"{algorithm:9s}: ok {r.ok}, plant samples outside the stroke {r.plant_limits['outside_stroke']}")
pd.DataFrame(
    {
        **{f"{a}, commanded": row(r.scores, r.limits) for a, r in compared.items()},
        **{f"{a}, plant": row(r.plant_scores, r.plant_limits) for a, r in compared.items()},
    }
).transpose()

# %% [markdown]
# The rows "commanded" score the poses sent to the controller, the rows "plant" the motion the simulated plate made
# of them: the difference is what the controller (its fixed-point words, its lag) and the actuators add to what
# the rider feels.

# %%
compared["tuned"].plot()
plt.show()
compared["tuned"].plot_legs()
plt.show()

# %% [markdown]
# The same run from the command line: `stewart-drake cue --platform gonzalez-dutra-2009 --drive ship-ss5
# --algorithm tuned --simulate --out DIR` writes the poses, the scores and these figures. The plant's motion as a
# Meshcat animation, saved beside them:

# %%
animation = compared["tuned"].animate()
path = animation.save(OUT / "ship-ss5.html")
print(path, f"{path.stat().st_size / 1e3:.0f} kB")
animation  # noqa: B018 (a notebook shows the last expression: the animation, inline)

# %% [markdown]
# The notebook's temporary folder is removed.

# %%
WORK.cleanup()
