# ---
# jupyter:
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Design check of a platform of your own
#
# A 6-6 platform defined here from its anchors, checked the way a designer would before building it:
# inverse kinematics along a motion, the reachable workspace, actuator sizing, stiffness and natural
# frequencies. Everything is SI (m, rad, s, N, kg); the figures convert to mm and degrees for reading.

# %%
# %matplotlib inline
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import stewart_drake as sd

WORK = tempfile.TemporaryDirectory(prefix="stewart-drake-design-")  # removed by the last cell, or when the kernel ends
OUT = Path(WORK.name)  # everything this notebook writes goes here

# %% [markdown]
# ## The platform
#
# Anchors on two circles: base pairs 24° apart every 120°, plate pairs offset by 60°, so that each leg leans
# (a platform with vertical legs has no stiffness against yaw). A 12 kg plate, a disc of radius 0.25 m.

# %%
deg = np.pi / 180
mass, radius = 12.0, 0.25
platform = sd.Platform.radial(
    0.35,
    np.array([-12, 12, 108, 132, 228, 252]) * deg,
    0.22,
    np.array([-48, 48, 72, 168, 192, 288]) * deg,
    name="my-hexapod",
    stroke=[0.45, 0.70],
    mass=mass,
    com=[0.0, 0.0, 0.02],
    inertia=np.diag([mass * radius**2 / 4, mass * radius**2 / 4, mass * radius**2 / 2]),
)
platform.to_yaml(OUT / "my-hexapod.yaml")
mine = sd.load_platform(OUT / "my-hexapod.yaml")  # the file reads back as the same platform
assert np.allclose(mine.base_anchors, platform.base_anchors) and np.allclose(mine.stroke, platform.stroke)
print(f"home height {platform.home_height * 1e3:.1f} mm, stroke {platform.stroke * 1e3} mm")
print((OUT / "my-hexapod.yaml").read_text()[:400])

# %% [markdown]
# ## Inverse kinematics along a motion
#
# A circle of 60 mm radius at home height while the plate yaws ±10°: `sd.ik` takes any `(..., 6)` array of
# poses and returns `(..., 6)` leg lengths with the stroke check.

# %%
s = np.linspace(0, 2 * np.pi, 200)
h = platform.home_height
poses = np.stack(
    [0.06 * np.cos(s), 0.06 * np.sin(s), np.full_like(s, h), 0 * s, 0 * s, 10 * deg * np.sin(2 * s)], axis=-1
)
r = sd.ik(platform, poses)
print("every pose within stroke:", bool(r.within_stroke.all()))

fig, ax = plt.subplots(figsize=(8, 3.5))
ax.plot(np.degrees(s), r.lengths * 1e3)
for limit in platform.stroke:
    ax.axhline(limit * 1e3, color="k", ls="--", lw=0.8)
ax.set(xlabel="phase along the circle [deg]", ylabel="leg length [mm]", title="IK along the circle, with the stroke")
plt.show()

# %% [markdown]
# ## Workspace
#
# The positions reachable at zero orientation on a 10 mm grid, and the largest rotations from home.

# %%
w = sd.workspace(platform, resolution=0.01)
print(f"volume {w.volume * 1e3:.2f} litres")
for lim in w.summary["rotation_limits"]:  # the dict `stewart-drake workspace --json` prints
    print(f"about {lim['axis']} {lim['direction']}: {lim['angle_deg']:+7.2f} deg, {lim['limit']} of leg {lim['leg']}")

# %%
edge = w.grid.boundary  # (n, 3) m: grid nodes inside the workspace with a neighbour outside
fig, ax = plt.subplots(1, 2, figsize=(9, 3.8))
ax[0].scatter(edge[:, 0], edge[:, 1], s=1, c=edge[:, 2], cmap="viridis")
ax[0].set(xlabel="x [m]", ylabel="y [m]", title="boundary, top view (colour: z)", aspect="equal")
ax[1].scatter(edge[:, 0], edge[:, 2], s=1, c=edge[:, 1], cmap="viridis")
ax[1].set(xlabel="x [m]", ylabel="z [m]", title="boundary, front view (colour: y)", aspect="equal")
plt.show()

# %% [markdown]
# ## Actuator sizing along the motion
#
# The same circle as a motion program (the motion language, mm and degrees), sized with the legs' masses.

# %%
program = OUT / "circle.stw"
program.write_text(
    f"""units mm, deg
mover(x = 60) en 0.5
FOR k := 1 TO 12 DO
    move(x = 60 * cos(2 * pi * k / 12), y = 60 * sin(2 * pi * k / 12), gama = 10 * sin(4 * pi * k / 12)) in 0.25
END
mover(0, 0, {h * 1e3:.3f}, 0, 0, 0) en 0.5
"""
)
trajectory = sd.Trajectory.from_program(program, platform)
sizing = sd.size(platform, trajectory, legs=True)
table = sizing.to_dict()["legs"]
columns = ["leg", "peak_force_n", "rms_force_n", "peak_speed_m_s", "peak_power_w", "min_length_m", "max_length_m"]
pd.DataFrame(table)[columns].round(3)

# %%
fig, ax = plt.subplots(figsize=(8, 3))
ax.bar(range(1, 7), [leg["peak_force_n"] for leg in table], label="peak |F|")
ax.bar(range(1, 7), [leg["rms_force_n"] for leg in table], width=0.5, label="RMS F")
ax.set(xlabel="leg", ylabel="force [N]", title="actuator forces along the program")
ax.legend()
plt.show()

# %% [markdown]
# ## Stiffness and natural frequencies at home
#
# With legs of 20 N/µm axial stiffness: the 6×6 stiffness about the rotation centre and the frequencies of
# the plate on its six springs.

# %%
home = platform.home_pose()
k = sd.stiffness(platform, home, leg_stiffness=2e7)
m = sd.modes(platform, home, leg_stiffness=2e7)
axes = ["x", "y", "z", "θx", "θy", "θz"]
print("K, rounded to 1 (N/m, N/rad, N·m/m, N·m/rad):")
print(pd.DataFrame(k.matrix.round(0), index=axes, columns=axes).to_string())
print("natural frequencies [Hz]:", np.round(m.frequencies_hz, 1))

fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
ax[0].imshow(np.log10(np.abs(k.matrix) + 1.0), cmap="viridis")
ax[0].set(title="log10 |K|", xticks=range(6), yticks=range(6))
ax[1].bar(range(1, 7), m.frequencies_hz)
ax[1].set(xlabel="mode", ylabel="frequency [Hz]", title="natural frequencies at home")
plt.show()

# %% [markdown]
# The notebook's temporary folder is removed.

# %%
WORK.cleanup()
