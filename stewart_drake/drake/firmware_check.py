"""Checking a firmware C file against the emulation: its ``sd_ik`` over workspace poses and, when it has
one, its ``sd_tick`` over the input stream of a closed-loop run (Python engine, recorded from a Diagram),
word for word."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import Platform
from stewart_drake.drake.simulation import Scenario, build_simulation
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.check import MAX_POSES, check_ik, check_tick
from stewart_drake.firmware.generate import generate
from stewart_drake.firmware.module import compile_user
from stewart_drake.fixedpoint.generic import pose_words
from stewart_drake.system.c_build import Compiler


def record_closed_loop(platform: Platform, config: ControllerConfig, trajectory="seed", duration: float = 0.5) -> list:
    """The per-tick inputs and outputs of the Python engine's controller in a closed-loop run:
    ``[(pose_words, measured counts, feed-forward words | None, state before, command words, state after)]``."""
    sim = build_simulation(Scenario(platform, trajectory, "fixed", config))
    law = sim.controller.law
    fmt = config.ik_format
    records = []
    orig = law.step

    def step(pid, ref, L, ff=None):
        out = orig(pid, ref, L, ff)
        cmd_words = np.round(out[0] / law.timing.command_range * 32768.0).astype(np.int64)
        records.append(
            (
                pose_words(np.asarray(ref, float), fmt),
                law.quantise(L),
                None if ff is None else law.feedforward_words(ff),
                np.asarray(pid).astype(np.int64),
                cmd_words,
                np.asarray(out[2]).astype(np.int64),
            )
        )
        return out

    law.step = step  # the system calls law.step at every tick: record each call
    sim.run(duration)
    return records


def check_firmware(
    path: Path,
    platform: Platform,
    config: ControllerConfig,
    n_poses: int = 100_000,
    seed: int = 0,
    trace: bool = False,
    duration: float = 0.5,
    compiler: Compiler | None = None,
) -> dict:
    """Compile ``path`` against the header generated for ``platform``/``config`` and compare it with the
    emulation; ``{"ik": ..., "tick": ... | None, "identical": bool}``."""
    if not (isinstance(n_poses, (int, np.integer)) and 1 <= n_poses <= MAX_POSES):
        raise FirmwareError(FirmwareError.POSES.format(limit=MAX_POSES, value=n_poses))
    if not (math.isfinite(duration) and 0 < duration <= 60):
        raise FirmwareError(FirmwareError.DURATION.format(value=duration))
    g = generate(platform, config)
    m = compile_user(path, g, compiler)
    if not m._has("sd_ik"):
        raise FirmwareError(FirmwareError.NO_IK.format(path=path))
    ik = check_ik(m, platform, config, n_poses, seed, trace)
    tick = check_tick(m, record_closed_loop(platform, config, duration=duration)) if m.has_tick else None
    same = ik["differing_poses"] == 0 and (tick is None or tick["differing_ticks"] == 0)
    return {"file": str(path), "platform": platform.name, "ik": ik, "tick": tick, "identical": same}
