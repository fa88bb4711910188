"""The compiled IK kernel (core.ik_kernel, core/ik_kernel.c) against the numpy reference
(kinematics.leg_lengths), its own sine/cosine against libm, and the numpy fallback."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from stewart_drake.core import ik_kernel
from stewart_drake.core.geometry import load_platform, load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import FkInputError, NotFiniteError, ShapeError

OWN = """
name: speed-ik-radial
length_unit: mm
radial:
  base_radius: 450.0
  base_angles_deg: [275.0, 25.0, 35.0, 145.0, 155.0, 265.0]
  top_radius: 250.0
  top_angles_deg: [315.0, 345.0, 75.0, 105.0, 195.0, 225.0]
stroke: [400.0, 800.0]
rotation_centre: [5.0, 15.0, -25.0]
"""


def test_compiled_ik_equals_numpy_ik(tmp_path):
    """Same formula and summation order: the lengths differ only through the last bit of a sine or
    cosine, so by at most 1e-15 m absolute on legs of 0.3–1.2 m (a few ulp; relative ≲ 3e-15), in both
    conventions, for workspace poses, poses with angles far beyond π (the reduction by π/2, and libm
    past 2^19 π/2), and in any batch shape."""
    path = tmp_path / "own.yaml"
    path.write_text(OWN)
    rng = np.random.default_rng(3)
    for p in (load_preset("utn-kinematic"), load_preset("gonzalez-dutra-2009"), load_platform(str(path))):
        q = random_poses(p, 20_000, seed=0, within_stroke=False)
        wide = q.copy()
        wide[:, 3:] = rng.uniform(-40, 40, (len(q), 3))
        huge = q[:100].copy()
        huge[:, 3:] = rng.uniform(-1e7, 1e7, (100, 3))
        for conv in ("utn", "zyx"):
            for poses in (q, wide, huge):
                ref = leg_lengths(p, poses, conv)
                got = ik_kernel.leg_lengths(p, poses, conv, engine="c")
                assert np.abs(got - ref).max() <= 1e-15
            flat = q.copy()
            flat[:, 3:] = 0.0  # sin 0 and cos 0 are exact on both sides: then the arithmetic is the same, bit for bit
            assert np.array_equal(ik_kernel.leg_lengths(p, flat, conv, engine="c"), leg_lengths(p, flat, conv))
        shaped = q[:24].reshape(2, 3, 4, 6)
        assert ik_kernel.leg_lengths(p, shaped).shape == (2, 3, 4, 6)
        assert np.abs(ik_kernel.leg_lengths(p, shaped) - leg_lengths(p, shaped)).max() <= 1e-15


def test_bad_input_is_named():
    p = load_preset("utn-dynamic")
    with pytest.raises(ShapeError):
        ik_kernel.leg_lengths(p, np.zeros((3, 5)))
    with pytest.raises(NotFiniteError, match="pose 2"):
        ik_kernel.leg_lengths(p, np.r_[[p.home_pose()], [p.home_pose() * np.nan]])
    with pytest.raises(FkInputError, match="engine must be"):
        ik_kernel.leg_lengths(p, p.home_pose(), engine="gpu")


def test_numpy_fallback_without_a_compiler(tmp_path):
    """No compiler and an empty cache: the numpy path runs, with the one-line note, the same lengths."""
    code = (
        "import json\n"
        "from stewart_drake.core.geometry import load_preset\n"
        "from stewart_drake.core import ik_kernel\n"
        "p = load_preset('utn-dynamic')\n"
        "print(json.dumps([ik_kernel.available(), ik_kernel.leg_lengths(p, p.home_pose() + 0.01).tolist()]))\n"
    )
    env = {**os.environ, "STEWART_DRAKE_CC": "/nonexistent/cc", "STEWART_DRAKE_CACHE": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stderr.strip() == ik_kernel.NO_COMPILER_NOTE
    avail, L = json.loads(out.stdout)
    p = load_preset("utn-dynamic")
    assert avail is False and L == leg_lengths(p, p.home_pose() + 0.01).tolist()


def test_portable_loop_equals_the_sse2_loop():
    """Where SSE2 is missing (other architectures) the plain C loop runs: built here with ``__SSE2__``
    undefined, it gives the same lengths bit for bit (the same operations in the same order)."""
    from stewart_drake.system.c_build import Source, build, load

    lib_path = build([Source(ik_kernel.SOURCE.name, path=ik_kernel.SOURCE)], opt=ik_kernel.OPT, flags=("-U__SSE2__",))
    ffi, lib = load(lib_path, ik_kernel.CDEF)
    p = load_preset("gonzalez-dutra-2009")
    q = np.ascontiguousarray(random_poses(p, 5000, seed=9, within_stroke=False))
    g = np.concatenate([p.base_anchors.ravel(), (p.top_anchors_per_leg - p.rotation_centre).ravel()])
    out = np.empty_like(q)
    lib.sd_ik(
        len(q), ffi.from_buffer("double[]", g), 0, ffi.from_buffer("double[]", q), ffi.from_buffer("double[]", out)
    )
    assert np.array_equal(out, ik_kernel.leg_lengths(p, q, engine="c"))
