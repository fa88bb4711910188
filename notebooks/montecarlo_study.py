# ---
# jupyter:
#   kernelspec:
#     display_name: Python 3 (ipykernel)
#     language: python
#     name: python3
# ---

# %% [markdown]
# # A Monte Carlo robustness study, read back with pandas and pyarrow
#
# `sd.montecarlo` repeats a closed-loop run with parameters drawn from laws (the `--vary` grammar): here
# anchor tolerances of ±0.5 mm, a gain error of ±20 % and either latency model, on the UTN dynamic preset.
# A real study runs hundreds of runs on a Dask cluster; this one runs four short runs in this process. The
# study's folder holds `results.parquet`, read back below with pandas and with pyarrow.

# %%
# %matplotlib inline
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
import pyarrow.parquet as pq

import stewart_drake as sd

WORK = tempfile.TemporaryDirectory(
    prefix="stewart-drake-montecarlo-"
)  # removed by the last cell, or when the kernel ends
OUT = Path(WORK.name)  # everything this notebook writes goes here
platform = sd.load_platform("utn-dynamic")

study = sd.montecarlo(
    platform,
    "seed",
    out=OUT / "study",
    runs=4,
    seed=7,
    vary=["anchor=±0.5mm", "gain_scale=±20%", "latency=sample|computation"],
    duration=0.2,
    workers=0,
)
print(sorted(p.name for p in (OUT / "study").iterdir()))

# %% [markdown]
# ## The table
#
# One row per run: its seed, every drawn parameter (SI), and the errors.

# %%
runs = pd.read_parquet(OUT / "study" / "results.parquet")
print(runs.shape)
runs.filter(regex="^(run|seed|gain|latency|max_|rms_|lost)")

# %% [markdown]
# The same file through pyarrow: its schema says each column's type.

# %%
table = pq.read_table(OUT / "study" / "results.parquet")
print(table.schema.to_string()[:800])
assert table.num_rows == len(runs) == 4

# %% [markdown]
# ## Which tolerance matters?
#
# The leg error against the drawn gain factor, and the study's own summary (percentiles, worst run, rank
# correlations).

# %%
fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
ax[0].scatter(runs["gain_scale"], runs["max_leg_error_m"] * 1e3)
ax[0].set(xlabel="gain_scale", ylabel="max |leg error| [mm]", title="error vs drawn gain")
(runs["max_leg_error_m"] * 1e3).plot.hist(ax=ax[1], bins=6)
ax[1].set(xlabel="max |leg error| [mm]", title="distribution (4 runs: a sample, not a law)")
plt.show()
pd.DataFrame(study.summary["metrics"]).T.filter(["p50", "p95", "max"])

# %% [markdown]
# The notebook's temporary folder is removed.

# %%
WORK.cleanup()
