"""The host's build of the generated firmware reads its gains from a table (``generate``'s ``host_files``,
``module.compile_generated``) and is optimised less (``module.HOST_OPT``): firmware that differs only in its
gains compiles once, the target's files are unchanged, and the host's build gives the words of the target's C
compiled at -O3 bit for bit, with several gain sets loaded side by side."""

import difflib
from dataclasses import replace

import numpy as np
import pytest

from stewart_drake.control import ControllerConfig
from stewart_drake.control.gains import counts_per_lsb
from stewart_drake.core.geometry import load_preset
from stewart_drake.firmware.check import workspace_poses
from stewart_drake.firmware.generate import GAIN_WORDS, generate
from stewart_drake.firmware.module import TickRunner, compile_generated
from stewart_drake.fixedpoint import QFormat
from stewart_drake.fixedpoint.generic import pose_words
from stewart_drake.spec import load_machine
from stewart_drake.system import c_build
from tests.firmware.firmware_cache import firmware_cache  # noqa: F401

NEWCOMER = "examples/newcomer-210kg.yaml"


def _changed(a: str, b: str) -> list[str]:
    return [
        line
        for line in difflib.unified_diff(a.splitlines(), b.splitlines(), n=0, lineterm="")
        if line[:1] in "+-" and line[:3] not in ("+++", "---")
    ]


def _variants(platform, fmt=QFormat(16, 1e-3, "tfr16")):
    """The designed configuration and two that differ from it only in what the host reads from the table:
    the gains scaled (a Monte Carlo run's ``gain_scale``) and a slower controller (a period sweep's)."""
    cfg = ControllerConfig.for_platform(platform, ik_format=fmt)
    g = cfg.gains
    scaled = replace(cfg, gains=replace(g, kp=g.kp * 1.3, ki=g.ki * 0.8, kd=g.kd * 0.7, kv=g.kv * 1.1))
    slower = ControllerConfig.for_platform(
        platform, timing=replace(cfg.timing, sample_period=2 * cfg.timing.sample_period), ik_format=fmt
    )
    return cfg, scaled, slower


@pytest.mark.parametrize("name", ["utn-dynamic", "gonzalez-dutra-2009", NEWCOMER])
def test_gain_variants_share_the_host_source_and_the_target_keeps_its_constants(name):
    p = load_machine(name).platform if name.endswith(".yaml") else load_preset(name)
    gens = [generate(p, cfg) for cfg in _variants(p)]
    first = gens[0]
    # the three differ in their gain words (else the test would prove nothing) and share the host's C
    assert len({g.gain_words for g in gens}) == 3
    assert all(g.host_files == first.host_files for g in gens)
    for g in gens:
        # the target's C: every gain a compile-time constant, the host's reads it from the table, and nothing
        # else differs (the header: the rate in its first comment)
        for word, value in zip(GAIN_WORDS, g.gain_words):
            assert f"#define {word} {value}\n" in g.files["sd_firmware.c"]
        changed = _changed(g.files["sd_firmware.c"], g.host_files["sd_firmware.c"])
        assert {line for line in changed if line.startswith("+#define")} == {
            f"+#define {word} sd_gains[{k}]" for k, word in enumerate(GAIN_WORDS)
        }
        assert len(changed) == 2 * len(GAIN_WORDS) + 2 * 2 + 1  # the defines, each block's 2-line comment, the table
        assert len(_changed(g.files["sd_firmware.h"], g.host_files["sd_firmware.h"])) == 2


def test_gain_variants_compile_once(monkeypatch, tmp_path):
    monkeypatch.setenv(c_build.CACHE_ENV, str(tmp_path))
    compiles = []
    run = c_build.run_compiler
    monkeypatch.setattr(
        c_build, "run_compiler", lambda cmd, what, timeout=None: compiles.append(what) or run(cmd, what)
    )
    p = load_preset("utn-kinematic")
    modules = [compile_generated(generate(p, cfg)) for cfg in _variants(p)]
    assert len(compiles) == 1
    assert len({m.path for m in modules}) == 3  # a copy of its own per gain set, each with its table
    compile_generated(generate(p, _variants(p)[1]), constants=True)  # the target's C: a library of its own
    assert len(compiles) == 2


def _closed_loop_inputs(module, platform, cfg, n: int, seed: int):
    """``n`` ticks' inputs near a closed loop's: a pose, readings within a few mm of its legs (``module``'s
    IK: the gains decide the commands, unsaturated mostly) and a feed-forward word."""
    rng = np.random.default_rng(seed)
    words = pose_words(workspace_poses(platform, n, seed), cfg.ik_format)
    legs, _ = module.ik(words)
    measured = legs * counts_per_lsb(cfg) + rng.integers(-300, 301, (n, 6))
    return words, measured, rng.integers(-3000, 3001, (n, 6))


@pytest.mark.parametrize(
    "name,fmt",
    [
        ("utn-dynamic", QFormat(16, 1e-3, "tfr16")),
        ("utn-kinematic", QFormat(12, 1e-3, "exact")),
        (NEWCOMER, QFormat(16, 3e-5, "tfr16")),
    ],
)
def test_host_build_equals_the_targets_c_at_O3(name, fmt):
    # the firmware is integer C: neither the table nor the optimisation level may change a word
    p = load_machine(name).platform if name.endswith(".yaml") else load_preset(name)
    cfgs = _variants(p, fmt)
    gens = [generate(p, cfg) for cfg in cfgs]
    table = [compile_generated(g) for g in gens]
    const = [compile_generated(g, constants=True, opt="-O3") for g in gens]
    # IK: every intermediate word, workspace poses and random words that saturate
    words = np.r_[
        pose_words(workspace_poses(p, 2000, 4), fmt), np.random.default_rng(4).integers(-32768, 32768, (2000, 6))
    ]
    words = np.clip(words, -(1 << fmt.frac_bits), (1 << fmt.frac_bits) - 1)
    for t, c in zip(table, const):
        assert all(np.array_equal(a, b) for a, b in zip(t.ik(words), c.ik(words)))
        assert all(np.array_equal(t.ik_trace(w), c.ik_trace(w)) for w in words[::100])
    # the tick: the three gain sets' runners interleaved (each table library keeps its own gains)
    runners = [(TickRunner(t), TickRunner(c)) for t, c in zip(table, const)]
    commands = [[] for _ in runners]
    w, measured, ff = _closed_loop_inputs(const[0], p, cfgs[0], 400, 5)
    for k in range(len(w)):
        for (rt, rc), out in zip(runners, commands):
            a, b = (
                rt.tick(w[k], measured[k], ff[k] if k % 3 else None),
                rc.tick(w[k], measured[k], ff[k] if k % 3 else None),
            )
            assert np.array_equal(a, b) and np.array_equal(rt.state(), rc.state()), k
            out.append(a)
    # the gain sets command differently: the table is read, not one set's constants
    assert not np.array_equal(commands[0], commands[1]) and not np.array_equal(commands[0], commands[2])
    assert np.mean(np.abs(np.array(commands)) < 32767) > 0.5  # mostly unsaturated: the gains decide them
