"""Checking a firmware C file against the emulation, word for word: its ``sd_ik`` over workspace poses
(``check_ik``) and its ``sd_tick`` over a recorded input stream (``check_tick``; the stream of a closed-loop
run is recorded by ``drake.firmware_check``)."""

from __future__ import annotations

import numpy as np

from stewart_drake.control.gains import ControllerConfig
from stewart_drake.core.geometry import Platform
from stewart_drake.core.sampling import random_poses
from stewart_drake.errors import FirmwareError
from stewart_drake.firmware.generate import TRACE_FIELDS
from stewart_drake.firmware.module import TickRunner
from stewart_drake.fixedpoint.generic import (
    leg_length_words,
    platform_words,
    pose_words,
    rotation_from_words,
    trig_words,
)

MAX_POSES = 100_000_000
CHUNK = 1 << 18


def trace_names() -> list[str]:
    """Names of the ``TRACE_WORDS`` intermediate words, e.g. ``R[1][2]``, ``leg3.y``."""
    names = [f"pose[{k}]" for k in range(6)] + [f"sin.{a}" for a in "xyz"] + [f"cos.{a}" for a in "xyz"]
    names += [f"R[{i}][{j}]" for i in range(3) for j in range(3)]
    names += [f"leg{i + 1}.{a}" for i in range(6) for a in "xyz"]
    names += [f"sq{i + 1}" for i in range(6)] + [f"length{i + 1}" for i in range(6)]
    assert len(names) == sum(n for _, n in TRACE_FIELDS)
    return names


def emulation_trace(platform: Platform, words, config: ControllerConfig) -> np.ndarray:
    """The emulation's intermediate words of one pose, in the layout of ``sd_ik_trace``."""
    fmt, conv = config.ik_format, config.convention
    w = np.asarray(words, dtype=np.int64).reshape(6)
    f = fmt.frac_bits
    lo, hi = -(1 << f), (1 << f) - 1
    s, c = trig_words(w[3:], fmt)
    R = rotation_from_words(w[3:], fmt, conv)
    r_T, B = platform_words(platform, fmt)
    acc_hi = (1 << (2 * fmt.word_bits - 1)) - 1
    legs, sqs = [], []
    for i in range(6):
        sq = 0
        for r in range(3):
            v = int(w[r])
            for k in range(3):
                if r_T[i, k]:
                    v = min(max(v + ((int(R[r, k]) * int(r_T[i, k])) >> f), lo), hi)
            v = min(max(v - int(B[i, r]), lo), hi)
            legs.append(v)
            sq = min(sq + v * v, acc_hi)
        sqs.append(min(sq, 2**31 - 1))
    lengths = leg_length_words(platform, w, fmt, conv)
    return np.concatenate([w, s, c, R.ravel(), legs, sqs, lengths]).astype(np.int64)


def workspace_poses(platform: Platform, n: int, seed: int = 0) -> np.ndarray:
    """``(n, 6)`` SI poses within stroke around home (``sampling.random_poses``: ±10 % of the stroke, ±15°)."""
    if not (isinstance(n, (int, np.integer)) and 1 <= n <= MAX_POSES):
        raise FirmwareError(FirmwareError.POSES.format(limit=MAX_POSES, value=n))
    return random_poses(platform, int(n), seed=seed)


def check_ik(module, platform: Platform, config: ControllerConfig, n: int, seed: int = 0, trace: bool = False) -> dict:
    """Compare ``module.sd_ik`` with the emulation on ``n`` workspace poses (in chunks)."""
    fmt, conv = config.ik_format, config.convention
    consts = platform_words(platform, fmt)
    if not (isinstance(n, (int, np.integer)) and 1 <= n <= MAX_POSES):
        raise FirmwareError(FirmwareError.POSES.format(limit=MAX_POSES, value=n))
    worst, differing, first = 0, 0, None
    for a in range(0, n, CHUNK):  # poses drawn chunk by chunk: memory stays bounded whatever n
        q = workspace_poses(platform, min(CHUNK, n - a), seed * 1_000_003 + a // CHUNK)
        words = pose_words(q, fmt)
        want = leg_length_words(platform, words, fmt, conv, consts)
        got, _ = module.ik(words)
        d = got - want
        bad = np.flatnonzero(np.any(d != 0, axis=-1))
        differing += int(bad.size)
        worst = max(worst, int(np.abs(d).max()))
        if bad.size and first is None:
            k = int(bad[0])
            first = {
                "index": a + k,
                "pose_si": q[k].tolist(),
                "pose_words": words[k].tolist(),
                "emulation_lengths": want[k].tolist(),
                "firmware_lengths": got[k].tolist(),
                "first_leg": int(np.flatnonzero(d[k])[0]) + 1,
            }
            if trace:
                first["trace"] = _trace(module, platform, config, words[k])
    return {"poses": int(n), "differing_poses": differing, "worst_lsb": worst, "first_difference": first}


def _trace(module, platform, config, words) -> dict:
    names = trace_names()
    emu = emulation_trace(platform, words, config)
    out = {"emulation": dict(zip(names, emu.tolist()))}
    if module.has_trace:
        fw = module.ik_trace(words)
        out["firmware"] = dict(zip(names, fw.tolist()))
        diff = np.flatnonzero(fw != emu)
        out["first_differing_word"] = names[int(diff[0])] if diff.size else None
    else:
        out["firmware"] = None
        out["first_differing_word"] = "lengths (the firmware has no sd_ik_trace to show its intermediate words)"
    return out


def check_tick(module, records: list) -> dict:
    """Run ``module.sd_tick`` from the first recorded state on the recorded inputs (its own state from
    then on) and compare its commands and state with the emulation's, tick by tick."""
    r = TickRunner(module)
    r.set_state(records[0][3])
    worst, differing, first = 0, 0, None
    for k, (w, m, ffw, _, cmd, state) in enumerate(records):
        c = r.tick(w, m, ffw).astype(np.int64)
        st = r.state()
        d = np.abs(c - cmd)
        if np.any(d) or np.any(st != state):
            differing += 1
            worst = max(worst, int(d.max()))
            if first is None:
                first = {
                    "tick": k,
                    "emulation_command": cmd.tolist(),
                    "firmware_command": c.tolist(),
                    "emulation_state": state.tolist(),
                    "firmware_state": st.tolist(),
                }
    return {"ticks": len(records), "differing_ticks": differing, "worst_command_lsb": worst, "first_difference": first}
