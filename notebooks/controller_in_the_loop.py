# ---
# jupyter:
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Controller in the loop: fixed point vs float, and the sample period
#
# `sd.simulate` runs the DSP's controller (16-bit IK in integer millimetres, Q15/Q31 PID) at its sample
# period against the closed-loop Drake model of the platform, or the same law in floating point. Here: both
# on the UTN dynamic preset along the seed's reference, then a small sweep of the sample period, and the
# run recorded as a Meshcat animation. Runs are kept short (0.3 s) so that the notebook runs in seconds.

# %%
# %matplotlib inline
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import stewart_drake as sd

WORK = tempfile.TemporaryDirectory(prefix="stewart-drake-loop-")  # removed by the last cell, or when the kernel ends
OUT = Path(WORK.name)  # everything this notebook writes goes here
platform = sd.load_platform("utn-dynamic")
reference = sd.Trajectory.seed()
DURATION = 0.3  # s

# %% [markdown]
# ## Fixed point vs float

# %%
runs = {kind: sd.simulate(platform, reference, controller=kind, duration=DURATION) for kind in ("fixed", "float")}
for kind, run in runs.items():
    worst = np.abs(run.log.length_error).max() * 1e3
    print(f"{kind:5s}: tracking ok {run.ok}, worst leg error {worst:.3f} mm, engine {run.summary['engine']}")

# %%
fig, ax = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
for kind, run in runs.items():
    log = run.log
    err = np.abs(log.length_error).max(axis=1) * 1e3
    ax[0].plot(log["t"], err, label=kind)
    ax[1].plot(log["t"], log["force"][:, 0], label=f"{kind}, leg 1")
ax[0].set(ylabel="max |leg error| [mm]", title="fixed-point vs float controller, seed reference")
ax[1].set(xlabel="t [s]", ylabel="force [N]")
ax[0].legend()
ax[1].legend()
plt.show()

# %% [markdown]
# The run's own figure (`SimulationResult.plot`) and its log as a pandas table:

# %%
runs["fixed"].plot()
plt.show()
frame = runs["fixed"].log.to_pandas()
frame.head()

# %% [markdown]
# ## A sweep of the sample period
#
# The gains are designed for each period. With 1 mm length words the fixed-point IK's quantisation (up to
# half a word per leg) is a large part of the error, so over this range the period changes it little: the
# numbers, not a rule of thumb, say by how much.

# %%
periods = [0.5e-3, 1e-3, 2e-3]
worst = []
for period in periods:
    run = sd.simulate(platform, reference, controller="fixed", duration=DURATION, period=period)
    worst.append(np.abs(run.log.length_error).max() * 1e3)
    print(f"T = {period * 1e3:g} ms: worst leg error {worst[-1]:.3f} mm, ok {run.ok}")

fig, ax = plt.subplots(figsize=(6, 3))
ax.plot(np.array(periods) * 1e3, worst, "o-")
ax.set(xlabel="sample period [ms]", ylabel="worst |leg error| [mm]", title="tracking vs sample period")
plt.show()

# %% [markdown]
# ## The animation
#
# A self-contained HTML page (Meshcat): shown inline in Jupyter, and saved to a file to open in a browser.

# %%
animation = runs["fixed"].animate()
path = animation.save(OUT / "fixed.html")
print(path, f"{path.stat().st_size / 1e3:.0f} kB")
animation  # noqa: B018 (a notebook shows the last expression: the animation, inline)

# %% [markdown]
# The notebook's temporary folder is removed.

# %%
WORK.cleanup()
