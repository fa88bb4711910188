"""Anchor tolerances per physical joint: on a 6-3 platform (legs sharing base joints) each base joint gets
one drawn offset, so the perturbed plant keeps every shared joint one point; platforms with six distinct
base anchors draw exactly what they drew before (replayability of studies written earlier)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from stewart_drake.cli import main
from stewart_drake.core.geometry import load_platform, load_platform_yaml
from stewart_drake.core.sanity import check_home
from stewart_drake.homotopy import architecture
from stewart_drake.montecarlo.scenario import KEYS, Study, base_joints, draw, plant_platform, run_seed
from stewart_drake.montecarlo.spec import parse_spec
from stewart_drake.montecarlo.study import settings_key, study_from_settings, study_key, study_settings
from tests.homotopy.test_platform_architectures import six_three_config

# Every law kind a key can take, so that a shift in the stream would show in some later key.
VARY = [
    "anchor=±0.5mm",
    "leg_offset=±0.1mm",
    "latency=sample|none",
    "actuator_lag=1ms..3ms",
    "plate_mass=±20%",
    "plate_com=±1mm",
    "gain_scale=0.9..1.1",
]
BEFORE = Path(__file__).with_name("draws_before_joints.json")
# The stored table predates the keys' renaming (payload_mass/payload_com set the plate's own mass and centre
# of mass, now plate_mass/plate_com) and the added payload (nominal 0 kg at the plate origin, drawn last).
RENAMES = (("payload_mass", "plate_mass"), ("payload_com", "plate_com"))
NEW_COLUMNS = {"payload_kg": 0.0, "payload_position_x_m": 0.0, "payload_position_y_m": 0.0, "payload_position_z_m": 0.0}


def _renamed(text: str) -> str:
    for old, new in RENAMES:
        text = text.replace(old, new)
    return text


LEG_BASE = [0, 0, 1, 1, 2, 2]


@pytest.fixture(scope="module")
def six_three(tmp_path_factory):
    """A 6-3 platform file (three base joints, two legs on each; plate anchors distinct) and its Platform."""
    cfg = six_three_config(0) | {"legs": {"max_force": 2000.0}}
    assert cfg["leg_base"] == LEG_BASE
    f = tmp_path_factory.mktemp("six_three") / "six-three.yaml"
    f.write_text(yaml.safe_dump(cfg, sort_keys=False))
    return f, load_platform_yaml(f)


def _old_stream(platform, seed: int, index: int) -> dict:
    """The draws of run ``index`` as written out from the stream layout of ``VARY``: a ``(6, 3)`` block of
    base offsets (one row per leg), ``(k, 3)`` plate offsets, then the later keys in ``KEYS`` order."""
    rng = np.random.default_rng(np.random.SeedSequence(run_seed(seed, index), spawn_key=(0,)))
    w = 0.5e-3
    assert list(KEYS)[:2] == ["anchor", "leg_offset"]  # the order written out below
    return {
        "base": rng.uniform(-w, w, size=(6, 3)),
        "top": rng.uniform(-w, w, size=(len(platform.top_anchors), 3)),
        "leg_offset": rng.uniform(-1e-4, 1e-4, size=6),
        "latency": ("sample", "none")[int(rng.integers(2))],
        "actuator_lag": rng.uniform(1e-3, 3e-3),
        "plate_mass": platform.mass * (1 + rng.uniform(-0.2, 0.2)),
        "plate_com": rng.uniform(-1e-3, 1e-3, size=3),
        "gain_scale": rng.uniform(0.9, 1.1),
    }


def _assert_later_keys_equal(d, old):
    np.testing.assert_array_equal(d.top_anchor_offset, old["top"])
    np.testing.assert_array_equal(d.leg_offset, old["leg_offset"])
    np.testing.assert_array_equal(d.plate_com_offset, old["plate_com"])
    assert (d.latency, d.actuator_lag, d.plate_mass, d.gain_scale) == (
        old["latency"],
        old["actuator_lag"],
        old["plate_mass"],
        old["gain_scale"],
    )


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009"])
def test_distinct_base_anchors_draw_as_before(name):
    """3-6 and 6-6 presets (six distinct base anchors): one base joint per leg, and every run's draw is
    bit for bit the stored table written by the draw code before this change, and the stream written out
    inline; the study settings (and so the study key) carry no ``base_joints``."""
    p = load_platform(name)
    first, leg_joint = base_joints(p)
    assert first.tolist() == leg_joint.tolist() == list(range(6))
    stored = json.loads(BEFORE.read_text())
    assert [_renamed(v) for v in stored["vary"]] == VARY
    st = Study(p, parse_spec(VARY), seed=stored["seed"], runs=2)
    for i, want in enumerate(stored["draws"][name]):
        _, d = draw(st, i)
        got = d.columns()
        want = {_renamed(k): v for k, v in want.items()} | NEW_COLUMNS
        assert list(got) == list(want)  # same columns, same order
        assert all(got[k] == want[k] for k in want), [k for k in want if got[k] != want[k]]
        old = _old_stream(p, stored["seed"], i)
        np.testing.assert_array_equal(d.base_anchor_offset, old["base"])
        _assert_later_keys_equal(d, old)
    assert "base_joints" not in study_settings(st)


def test_six_three_base_joints_move_as_one(six_three):
    """Every run on a 6-3 platform: each shared base joint's two legs stay at one point, exactly; the
    table has one column per joint and axis; a joint's offset is its first leg's row of the old per-leg
    block (whose other rows would have split the joints) and every later key draws what it drew before;
    the perturbed platform is again a 6-3 platform that passes the loader's checks."""
    f, p = six_three
    first, leg_joint = base_joints(p)
    assert first.tolist() == [0, 2, 4] and leg_joint.tolist() == LEG_BASE
    st = Study(p, parse_spec(VARY), seed=9, runs=6)
    for i in range(st.runs):
        _, d = draw(st, i)
        old = _old_stream(p, st.seed, i)
        assert d.base_anchor_offset.shape == (3, 3)
        np.testing.assert_array_equal(d.base_anchor_offset, old["base"][[0, 2, 4]])
        _assert_later_keys_equal(d, old)
        # the old per-leg block would have split each joint by far more than the coincidence limit
        assert np.linalg.norm(old["base"][0::2] - old["base"][1::2], axis=1).min() > 1e-6
        cols = [c for c in d.columns() if c.startswith("anchor_base")]
        assert cols == [f"anchor_base{j}_{a}_m" for j in (1, 2, 3) for a in "xyz"]
        pp = plant_platform(p, d)
        b = pp.base_anchors
        for j in range(3):
            np.testing.assert_array_equal(b[2 * j], b[2 * j + 1])
        assert not np.array_equal(b, p.base_anchors)
        # per leg, the move is its joint's offset (one addition of a metre-scale number: 1 ulp ~ 1e-16 m)
        np.testing.assert_allclose(b - p.base_anchors, d.base_anchor_offset[LEG_BASE], rtol=0, atol=1e-15)
        assert architecture(pp).kind == "6-3" and base_joints(pp)[1].tolist() == LEG_BASE
        check_home(pp)
        # written as a platform file (joints listed once, leg_base) it loads, through every file check
        cfg = yaml.safe_load(f.read_text()) | {
            "base_anchors": b[first].tolist(),
            "top_anchors": pp.top_anchors.tolist(),
        }
        g = f.with_name(f"perturbed-{i}.yaml")
        g.write_text(yaml.safe_dump(cfg, sort_keys=False))
        np.testing.assert_array_equal(load_platform_yaml(g).base_anchors, b)


def test_six_three_study_table_key_and_replay(six_three, tmp_path, capsys):
    """A short 6-3 study: the table has per-joint base columns (three joints), the summary and its
    sensitivity name them, ``study.json`` records the joints (the key differs from a split-joint study's)
    and round-trips to the same key, and a replayed run is bit-identical to its row."""
    f, p = six_three
    out = tmp_path / "mc"
    args = ["montecarlo", "--platform", str(f), "--fit", "--runs", "3", "--seed", "4", "--vary", *VARY]
    assert main([*args, "--duration", "0.1", "--workers", "0", "--out", str(out), "--no-progress", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    header = (out / "results.csv").read_text().splitlines()[0].split(",")
    base_cols = [c for c in header if c.startswith("anchor_base")]
    assert base_cols == [f"anchor_base{j}_{a}_m" for j in (1, 2, 3) for a in "xyz"]
    assert [c for c in header if c.startswith("anchor_top")] == [
        f"anchor_top{j}_{a}_m" for j in range(1, 7) for a in "xyz"
    ]
    assert set(base_cols) <= set(summary["varied_parameters"])
    ranked = {d["parameter"] for d in summary["sensitivity"]["max_leg_error_m"]}
    assert ranked <= set(summary["varied_parameters"]) and ranked & set(base_cols)
    stored = json.loads((out / "study.json").read_text())
    assert stored["settings"]["base_joints"] == LEG_BASE
    st = study_from_settings(stored["settings"], stored["runs"])
    assert study_key(st) == stored["key"] == summary["key"]
    split = {k: v for k, v in stored["settings"].items() if k != "base_joints"}  # the settings as written before
    assert stored["key"] != settings_key(split)
    assert main(["montecarlo", "--out", str(out), "--replay", "2", "--no-animation", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["bit_identical"] and result["differing_columns"] == []
