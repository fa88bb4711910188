"""The firmware certificate (``firmware.certify``): the interval recipe against the bit-exact emulation,
the soundness of its hulls and error enclosures, and the verdicts the issue names.

The checks against samples here use a few thousand poses, not the 10^7 of the done-when: CI must stay
short; ``benchmarks/bench_certify.py --poses 10000000`` runs the full comparison by hand."""

from __future__ import annotations

import json

import numpy as np
import pytest
from flint import arb, ctx

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform, load_preset
from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.errors import CertifyError
from stewart_drake.firmware.certify.box import parse_box, workspace_box
from stewart_drake.firmware.certify.certificate import certify
from stewart_drake.firmware.certify.intervals import RangeTable
from stewart_drake.firmware.certify.recipe import Model, evaluate, isqrt_nearest, word_names
from stewart_drake.firmware.certify.sampling import sample_box, word_pose_si
from stewart_drake.firmware.check import emulation_trace
from stewart_drake.fixedpoint.generic import QFormat, leg_length_words
from stewart_drake.fixedpoint.q15 import SaturationCounter

FORMATS = [
    ("utn-kinematic", QFormat(16, 1e-3, "tfr16")),
    ("utn-dynamic", QFormat(16, 2e-5, "exact")),  # saturates: the hulls must still match
    ("gonzalez-dutra-2009", QFormat(12, 1e-3, "exact")),
]


class _Config:
    def __init__(self, fmt):
        self.ik_format, self.convention = fmt, "utn"


def _words_in_box(model, box, n, seed):
    lo, hi = box.words(model.fmt)
    rng = np.random.default_rng(seed)
    return lo + np.floor(rng.random((n, 6)) * (hi - lo + 1)).astype(np.int64)


@pytest.mark.parametrize("name,fmt", FORMATS, ids=[f[0] for f in FORMATS])
def test_a_one_pose_cell_gives_the_emulations_words(name, fmt):
    """At a cell of one pose the interval recipe is the emulation, word for word (``emulation_trace`` is
    independent scalar code): the certifier cannot drift from the firmware it certifies."""
    platform = load_platform(name)
    model = Model.build(platform, fmt)
    w = _words_in_box(model, workspace_box(platform), 60, 1)
    lo, hi = evaluate(model, w, w).post(model)
    assert np.array_equal(lo, hi)
    want = np.array([emulation_trace(platform, w[k], _Config(fmt)) for k in range(len(w))])
    assert np.array_equal(lo, want)


@pytest.mark.parametrize("name,fmt", FORMATS, ids=[f[0] for f in FORMATS])
def test_cell_hulls_and_error_enclosures_hold_every_pose_inside(name, fmt):
    """Random small cells: every word of every pose inside lies in the cell's hull, and every pose's
    L_emulation - L_double lies in the cell's error enclosure (where it is finite)."""
    platform = load_platform(name)
    model = Model.build(platform, fmt)
    rng = np.random.default_rng(2)
    c_lo = _words_in_box(model, workspace_box(platform), 40, 3)
    c_hi = c_lo + rng.integers(0, 40, (40, 6))
    ev = evaluate(model, c_lo, c_hi)
    post_lo, post_hi = ev.post(model)
    for k in range(40):
        pts = c_lo[k] + np.floor(rng.random((50, 6)) * (c_hi[k] - c_lo[k] + 1)).astype(np.int64)
        pe = evaluate(model, pts, pts)
        pl, _ = pe.post(model)
        assert np.all(pl >= post_lo[k]) and np.all(pl <= post_hi[k])
        assert np.all(pe.pre_lo >= ev.pre_lo[k]) and np.all(pe.pre_lo <= ev.pre_hi[k])
        assert not np.any(pe.possible & ~ev.possible[k])  # a clamp at a pose is flagged in its cell
        err = leg_length_words(platform, pts, fmt) - leg_lengths(platform, word_pose_si(model, pts)) / fmt.length_lsb
        fin = np.isfinite(ev.err_lo[k])
        assert np.all(err[:, fin] >= ev.err_lo[k, fin]) and np.all(err[:, fin] <= ev.err_hi[k, fin])


def test_error_enclosure_contains_the_exact_ik_in_arb_balls():
    """The float side made rigorous: the leg length at the word pose computed in arb balls (python-flint,
    200 bits) lies inside L_words - [err_lo, err_hi] at single poses."""
    platform = load_platform("utn-kinematic")
    fmt = QFormat(16, 1e-4, "tfr16")
    model = Model.build(platform, fmt)
    w = _words_in_box(model, workspace_box(platform), 5, 4)
    ev = evaluate(model, w, w)
    Lw = leg_length_words(platform, w, fmt)
    r_T = platform.top_anchors_per_leg - platform.rotation_centre
    ctx.prec = 200
    for k in range(len(w)):
        ang = [arb(int(v)) * arb.pi() / (1 << fmt.frac_bits) for v in w[k, 3:]]
        s = [a.sin() for a in ang]
        c = [a.cos() for a in ang]
        # utn: R = Ry(b) Rx(a) Rz(g) (the convention's definition; checked against rotation_matrix below)
        R = [
            [c[1] * c[2] + s[1] * s[0] * s[2], -c[1] * s[2] + s[1] * s[0] * c[2], s[1] * c[0]],
            [c[0] * s[2], c[0] * c[2], -s[0]],
            [-s[1] * c[2] + c[1] * s[0] * s[2], s[1] * s[2] + c[1] * s[0] * c[2], c[1] * c[0]],
        ]
        Rf = rotation_matrix(word_pose_si(model, w[k])[3:], "utn")
        assert np.allclose([[float(x.mid()) for x in row] for row in R], Rf, atol=1e-15)
        p = [arb(int(v)) * arb(fmt.length_lsb) for v in w[k, :3]]
        for i in range(6):
            v = [
                p[r] + sum(R[r][j] * arb(float(r_T[i, j])) for j in range(3)) - arb(float(platform.base_anchors[i, r]))
                for r in range(3)
            ]
            L = (v[0] ** 2 + v[1] ** 2 + v[2] ** 2).sqrt() / arb(fmt.length_lsb)
            assert float(Lw[k, i]) - ev.err_hi[k, i] <= float(L.lower())
            assert float(L.upper()) <= float(Lw[k, i]) - ev.err_lo[k, i]


def test_range_table_gives_the_exact_min_and_max():
    v = np.random.default_rng(5).integers(-1000, 1000, 777)
    t = RangeTable(v, offset=-10)
    rng = np.random.default_rng(6)
    a = rng.integers(-10, 767, 300)
    b = np.minimum(a + rng.integers(0, 300, 300), 766)
    mn, mx = t.query(a, b)
    assert all(mn[k] == v[a[k] + 10 : b[k] + 11].min() and mx[k] == v[a[k] + 10 : b[k] + 11].max() for k in range(300))


def test_isqrt_nearest_is_the_nearest_of_two_rule():
    S = np.r_[np.arange(0, 5000), np.random.default_rng(0).integers(0, 2**31 - 1, 5000)]
    y = isqrt_nearest(S)
    assert np.all(np.abs(y * y - S) <= np.minimum(np.abs((y + 1) ** 2 - S), np.abs((y - 1) ** 2 - S)))


def test_default_format_bound_holds_and_is_within_twice_the_sampled_worst():
    """utn-kinematic's workspace box at the default format: no saturation; the proven bound is above the
    worst of 3,000 random + 37,000 adversarial poses and within twice it (the benchmark repeats this on 10^7)."""
    platform = load_preset("utn-kinematic")
    fmt = QFormat(16, 1e-3, "tfr16")
    box = workspace_box(platform)
    cert = certify(platform, fmt, box, max_cells=30_000)
    assert not cert.saturation_possible
    model = Model.build(platform, fmt)
    s = sample_box(model, *box.words(fmt), 3000, seed=0, adversarial=6)
    worst_mm = s.worst_err * fmt.length_lsb * 1e3
    bound = np.array(cert.error_bound_mm)
    assert np.all(bound >= worst_mm)
    assert bound.max() <= 2 * worst_mm.max()
    names = word_names()
    proven = {w.name: w for w in cert.words}
    for k, n in enumerate(names):
        assert proven[n].min <= s.word_min[k] and s.word_max[k] <= proven[n].max, n


def test_lsb_2e5_saturates_with_a_witness_and_1e4_proves_none(capsys):
    """The issue's pair, through the command: utn-kinematic over its workspace box (±60 mm, 120–250 mm,
    ±0.08π) saturates at a 20 µm LSB, with a witness the emulation itself saturates at (exit 1); at 100 µm
    the certificate proves no saturation anywhere (exit 0)."""
    platform = load_preset("utn-kinematic")
    args = ["firmware", "certify", "--platform", "utn-kinematic", "--workspace", "--max-cells", "20000", "--json"]
    assert main(args + ["--length-lsb", "2e-5"]) == 1
    d = json.loads(capsys.readouterr().out)
    assert d["box"] == {"px": [-60, 60], "py": [-60, 60], "pz": [120, 250], **{k: [-0.08, 0.08] for k in "abg"}}
    assert d["saturation_possible"] is True and d["witness"]["saturates"]
    assert {"name", "min", "max", "headroom_bits", "saturation"} <= set(d["words"][0])
    assert d["error_bound_mm"] == [None] * 6
    w = np.array(d["witness"]["pose_words"])
    fmt = QFormat(16, 2e-5, "tfr16")
    lo, hi = workspace_box(platform).words(fmt)
    assert np.all(w >= lo) and np.all(w <= hi)
    with SaturationCounter() as sat:  # the emulation itself saturates at the witness
        leg_length_words(platform, w, fmt)
    assert sat.counts["generic.sqrt"] >= 1
    assert main(args + ["--length-lsb", "1e-4"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["saturation_possible"] is False and d["unresolved_count"] == 0 and d["witness"] is None
    assert all(w["saturation"] == "impossible" for w in d["words"] if not w["benign"])
    assert all(0 < e < 1.0 for e in d["error_bound_mm"])


@pytest.mark.parametrize(
    "box,message",
    [
        (["pz=250..120"], CertifyError.BOX_ORDER.format(value="pz=250..120")),
        (["q=1..2"], CertifyError.BOX_WORD.format(value="q=1..2")),
        (["a=-2..2"], CertifyError.BOX_ANGLE.format(value="a=-2..2")),
        (["px=1..2", "px=3..4"], CertifyError.BOX_TWICE.format(key="px", value="px=3..4")),
    ],
)
def test_bad_box_is_one_line_exit_2(box, message, capsys):
    assert main(["firmware", "certify", "--platform", "utn-kinematic", "--box", *box]) == 2
    assert capsys.readouterr().err.strip().endswith(message)


def test_a_user_platform_file(tmp_path, capsys):
    """A platform of our own (the radial template), its default workspace box."""
    yaml = tmp_path / "mine.yaml"
    assert main(["init", "--platform-template", "radial"]) == 0
    yaml.write_text(capsys.readouterr().out)
    platform = load_platform(str(yaml))
    cert = certify(platform, QFormat(16, 1e-3, "tfr16"), workspace_box(platform), max_cells=20_000)
    assert not cert.saturation_possible
    model = Model.build(platform, cert.fmt)
    s = sample_box(model, *workspace_box(platform).words(cert.fmt), 2000, seed=1)
    assert np.all(np.array(cert.error_bound_mm) >= s.worst_err * 1e-3 * 1e3)


def test_optimize_meets_the_budget_with_a_proof_and_its_firmware_matches_the_emulation():
    """A small box and a 0.5 mm budget: the chosen formats have a proven bound within the budget and no
    possible saturation; their generated sd_ik (compiled) equals the emulation on the check's poses and
    its sampled error is within the budget; the simulation-only choice never has fewer proven guarantees
    than it claims silently (if it is not provable, it is reported as such)."""
    from stewart_drake.control.gains import ControllerConfig
    from stewart_drake.firmware.certify.optimize import optimize
    from stewart_drake.firmware.certify.sampling import length_errors
    from stewart_drake.firmware.check import check_ik
    from stewart_drake.firmware.module import compile_generated

    platform = load_preset("utn-kinematic")
    box = parse_box(
        ["px=-10..10", "py=-10..10", "pz=150..170", "a=-0.02..0.02", "b=-0.02..0.02", "g=-0.02..0.02"], platform
    )
    config = ControllerConfig.for_platform(platform)
    res = optimize(platform, config, box, 0.5e-3, "bits", max_cells=4000, search_cells=4000, samples=2000)
    c = res.chosen
    assert c is not None and not c.saturation_possible and c.error_mm <= 0.5
    assert c.fmt.word_bits <= res.default.fmt.word_bits
    assert res.default.error_mm is None or res.default.error_mm > 0.5  # the default 1 mm LSB cannot meet it
    model = Model.build(platform, c.fmt)
    w = _words_in_box(model, box, 5000, 9)
    assert np.abs(length_errors(model, w)).max() * c.fmt.length_lsb <= 0.5e-3
    r = check_ik(compile_generated(res.firmware), platform, res.firmware.config, 20_000)
    assert r["differing_poses"] == 0
    assert res.simulation_only is not None and res.simulation_only_proven is not None
    assert res.simulation_only_proven.fmt == res.simulation_only.fmt


def test_tick_ranges_hold_along_runs_of_the_fixed_point_law():
    """sd_tick's certificate against the law itself (``control.FixedPointLaw``, bit-exact to sd_tick):
    a held error of 5 mm winds the integrator up to the proven level and no further (speed 0, no
    feed-forward: anti-windup proven); random measurement walks within 0.1 m/s keep the filters and terms in
    their proven ranges."""
    from stewart_drake.control import ControllerConfig
    from stewart_drake.control.laws import FixedPointLaw
    from stewart_drake.firmware.certify.tick import certify_tick

    platform = load_preset("utn-dynamic")
    config = ControllerConfig.for_platform(platform)
    law = FixedPointLaw(platform, config)
    ref = platform.home_pose()
    sp = law.setpoint_words(ref) * config.ik_format.length_lsb
    res = config.timing.sensor_resolution

    still = certify_tick(config, 5e-3, 0.0, 0.0)
    assert still.anti_windup
    words = {w.name: w for w in still.words}
    top = words["integrator (Q31)"].max
    state = law.initial_pid_state(sp, np.zeros(6))
    state[:6] = 2.0e9  # near the top: at 5 mm the integrator grows ~1.85e5 per tick until the command saturates
    for _ in range(600):
        _, _, state, _ = law.step(state, ref, sp - 5e-3, None)
    assert state[:6].max() <= top
    # a one-count error then walks it by ki (370) per tick up to the level, and no further: tight and sound
    state[:6] = top - 20_000
    peak = -np.inf
    for _ in range(200):
        _, _, state, _ = law.step(state, ref, sp - res, None)
        peak = max(peak, state[:6].max())
    assert top >= peak > top - words["integrator increment (Q31)"].max / 500 - 1

    moving = certify_tick(config, 5e-3, 0.1, 0.0)
    words = {w.name: w for w in moving.words}
    rng = np.random.default_rng(3)
    state = law.initial_pid_state(sp, np.zeros(6))
    m = sp.copy()
    dfilt_seen = [0, 0]
    for _ in range(300):
        m = np.clip(m + rng.uniform(-0.1, 0.1, 6) * config.timing.sample_period, sp - 5e-3 + res, sp + 5e-3 - res)
        _, _, state, _ = law.step(state, ref, m, None)
        df = state[12:18]
        dfilt_seen = [min(dfilt_seen[0], df.min()), max(dfilt_seen[1], df.max())]
    w = words["derivative filter"]
    assert w.min <= dfilt_seen[0] and dfilt_seen[1] <= w.max


@pytest.mark.parametrize("convention", ["utn", "zyx"])
def test_rotation_hulls_near_zero_angles_are_exact(convention):
    """Cells around zero angles, where the intervals leave R's clamp undecided and the enumeration takes
    over: the hull of every rotation word equals the brute-force hull over every angle word of the cell."""
    from stewart_drake.fixedpoint.generic import rotation_from_words

    platform = load_preset("utn-kinematic")
    fmt = QFormat(12, 1e-3, "exact")
    model = Model.build(platform, fmt, convention)
    rng = np.random.default_rng(8)
    for _ in range(4):
        a_lo = rng.integers(-30, 5, 3)
        c_lo = np.r_[0, 0, 200, a_lo][None, :]
        c_hi = np.r_[0, 0, 200, a_lo + rng.integers(3, 25, 3)][None, :]
        ev = evaluate(model, c_lo, c_hi)
        grids = np.meshgrid(*[np.arange(c_lo[0, 3 + k], c_hi[0, 3 + k] + 1) for k in range(3)], indexing="ij")
        w = np.stack([g.ravel() for g in grids], axis=-1)
        R = rotation_from_words(w, fmt, convention).reshape(-1, 9)  # clamped words, as the firmware holds them
        lo, hi = ev.post(model)
        names = word_names()
        for j in range(9):
            k = names.index(f"R[{j // 3}][{j % 3}]")
            assert lo[0, k] <= R[:, j].min() and R[:, j].max() <= hi[0, k]
            if j in (0, 4, 8) and not ev.possible[0, k]:  # near 1: enumerated, decided, so exact
                assert (lo[0, k], hi[0, k]) == (R[:, j].min(), R[:, j].max())


def test_certify_tick_option(capsys):
    args = ["firmware", "certify", "--platform", "utn-dynamic", "--max-cells", "2000", "--tick", "--json"]
    main(args + ["--tick-speed", "0"])  # the IK verdict at this tiny budget does not matter here
    tick = json.loads(capsys.readouterr().out)["tick"]
    assert tick["anti_windup_proven"] is True and tick["no_wrap"] is True
    assert {w["name"] for w in tick["words"]} >= {"integrator (Q31)", "derivative filter", "command (Q15)"}
    assert main(args + ["--tick-error", "-1"]) == 2
    assert capsys.readouterr().err.endswith("--tick-error must be >= 0, got -1\n")


def test_tp17_one_pose_cells_give_tp17_trace_and_the_bound_holds():
    """The seed's firmware: at cells of one pose the interval recipe gives every word of ``tp17_trace``;
    the certificate over the workspace box proves no saturation and its bound is above the sampled worst
    error of tp17 against utn-kinematic's float IK (a = 612.5 mm)."""
    from stewart_drake.firmware.certify.tp17_recipe import evaluate_tp17, tp17_model
    from stewart_drake.fixedpoint.tp17 import dsp_poses_to_si, tp17_leg_lengths, tp17_trace

    platform = load_preset("utn-kinematic")
    model = tp17_model(platform)
    rng = np.random.default_rng(4)
    lo, hi = np.array([-60, -60, 120, -2621, -2621, -2621]), np.array([60, 60, 250, 2621, 2621, 2621])
    w = lo + np.floor(rng.random((200, 6)) * (hi - lo + 1)).astype(np.int64)
    ev = evaluate_tp17(model, w, w)
    q = np.c_[w[:, :3].astype(float), w[:, 3:] / 32768.0]
    tr = tp17_trace(q)
    want = np.concatenate([w, tr.sin, tr.cos, tr.R.reshape(-1, 9), tr.leg.reshape(-1, 18), tr.L32, tr.lengths], axis=1)
    assert np.array_equal(ev.pre_lo, want) and np.array_equal(ev.pre_hi, want)
    cert = certify(platform, model.fmt, workspace_box(platform), max_cells=20_000, implementation="tp17")
    assert not cert.saturation_possible
    w = lo + np.floor(rng.random((20_000, 6)) * (hi - lo + 1)).astype(np.int64)
    q = np.c_[w[:, :3].astype(float), w[:, 3:] / 32768.0]
    err = np.abs(tp17_leg_lengths(q) - leg_lengths(platform, dsp_poses_to_si(q)) * 1e3).max(axis=0)
    assert np.all(np.array(cert.error_bound_mm) >= err)
