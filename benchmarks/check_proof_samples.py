"""10⁶ random poses of the required box, checked by the toolkit's IK on a proven design: none may leave the
stroke or put a plate anchor at or below the base (the test suite checks 20 000 to stay fast). With
``--performance N``, the first N of them also go through the toolkit's envelope sizing, loaded stiffness and
condition number (``synthesis.performance.sampled_performance``): none may exceed the performance proof's bounds
of force, speed and condition or fall below its frequency bound; it prints each bound over the sampled worst.

    PYTHONPATH=. python benchmarks/check_proof_samples.py [--platform DIR/design.yaml --requirements R.yaml]
        [--performance 100000]

Without --platform it synthesises the design of seed 001's requirements (as the report does) first.
"""

from __future__ import annotations

import argparse
import time
from importlib import resources

import numpy as np

from stewart_drake.core.geometry import load_platform
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sanity import plate_anchor_heights
from stewart_drake.synthesis.performance import prove_requirements_performance, sampled_performance
from stewart_drake.synthesis.proof import prove_requirements_box
from stewart_drake.synthesis.requirements import load_requirements
from stewart_drake.synthesis.synthesize import synthesize

DEFAULT = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--requirements", default=str(DEFAULT))
    ap.add_argument("--platform", default=None)
    ap.add_argument("--poses", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--performance", type=int, default=0, help="poses checked against the performance proof")
    args = ap.parse_args(argv)
    req = load_requirements(args.requirements)
    p = load_platform(args.platform) if args.platform else synthesize(req, budget=240, seed=args.seed).platform
    proof = prove_requirements_box(p, req.box_lo, req.box_hi, req.convention)
    print(
        f"proof: {proof.status} ({proof.cells_examined} cells); leg bounds {proof.length_bounds} m, stroke {p.stroke.tolist()} m"
    )
    rng = np.random.default_rng(args.seed)
    worst, zmin, t0 = -np.inf, np.inf, time.perf_counter()
    for s in range(0, args.poses, 100_000):
        n = min(100_000, args.poses - s)
        poses = p.home_pose() + req.box_lo + rng.random((n, 6)) * (req.box_hi - req.box_lo)
        L = leg_lengths(p, poses, req.convention)
        worst = max(worst, float(np.max(p.L_min - L)), float(np.max(L - p.L_max)))
        zmin = min(zmin, float(plate_anchor_heights(p, poses, req.convention).min()))
    print(
        f"{args.poses} poses in {time.perf_counter() - t0:.1f} s: worst excess beyond the stroke {worst * 1e3:.4f} mm "
        f"(negative: inside), lowest plate anchor {zmin:.4f} m"
    )
    bad = worst > 0 or zmin <= 0
    print("FAIL: a pose leaves the proven box" if bad else "ok: no pose leaves the stroke")
    if args.performance:
        bad |= _performance(p, req, args.performance, args.seed)
    return 1 if bad or proof.status != "proven" else 0


def _performance(p, req, n: int, seed: int) -> bool:
    """Check n random poses against the performance proof's bounds; True when one breaks a proven bound."""
    perf = prove_requirements_performance(p, req)
    res = perf.results
    print(f"performance proof ({perf.cells_examined} cells, {perf.seconds:.1f} s): " + ", ".join(
        f"{k} {r['status']} {r['bound']}" for k, r in res.items()
    ))  # fmt: skip
    rng = np.random.default_rng(seed + 1)
    worst = {k: (np.inf if k == "frequency" else -np.inf) for k in res}
    t0 = time.perf_counter()
    for s in range(0, n, 20_000):
        poses = p.home_pose() + req.box_lo + rng.random((min(20_000, n - s), 6)) * (req.box_hi - req.box_lo)
        v = sampled_performance(p, poses, req.v_max, req.a_max, req.stiffness, req.convention)
        for k in worst:
            worst[k] = min(worst[k], v[k].min()) if k == "frequency" else max(worst[k], v[k].max())
    bad = False
    for k, r in res.items():
        if r["bound"] is None:
            continue
        broken = worst[k] < r["bound"] if k == "frequency" else worst[k] > r["bound"]
        bad |= bool(broken)
        factor = worst[k] / r["bound"] if k == "frequency" else r["bound"] / worst[k]
        print(f"  {k}: sampled worst {worst[k]:.6g}, proven bound {r['bound']:.6g} ({factor:.2f}x)"
              + (" FAIL: beyond the bound" if broken else ""))  # fmt: skip
    print(f"{n} poses in {time.perf_counter() - t0:.1f} s")
    return bad


if __name__ == "__main__":
    raise SystemExit(main())
