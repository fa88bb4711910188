"""The options a firmware module was generated with, recorded in its files (a fingerprint) and read back by
``firmware check``: a check with other options compares the C against another emulation and reported
hundreds of differences with no hint. ``check`` takes the recorded options by default and names an option
given on its command line that differs from the recorded one."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np

from stewart_drake.core.geometry import Platform
from stewart_drake.core.platform_file import platform_yaml
from stewart_drake.errors import FirmwareError

# The options of ``firmware generate`` that define the module (their command-line defaults).
DEFAULTS = {
    "platform": "utn-dynamic",
    "word_bits": 16,
    "length_lsb": 1e-3,
    "trig": "tfr16",
    "convention": "utn",
    "rate": 1000.0,
    "sensor_resolution": 1e-5,
    "trajectory": None,
}
# Recorded beside the options (not an option): the content hash of the platform the module was generated for.
PLATFORM_HASH = "platform_hash"
TAG = "stewart-drake-options:"
_LINE = re.compile(r"/\* " + re.escape(TAG) + r" (\{.*?\}) \*/")
# bytes read from the top of a file when looking for the fingerprint (it is on the first lines)
HEAD_BYTES = 4096


def platform_hash(platform: Platform) -> str:
    """A content hash of ``platform`` (16 hex digits of the SHA-256 of its platform file in SI): equal for the
    same geometry, mass properties and legs however the platform was written or named."""
    text = platform_yaml(platform.replace(name="", description=""), header="")
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


def fingerprint_line(options: dict) -> str:
    """The comment line recording ``options`` (``DEFAULTS``' keys, and ``PLATFORM_HASH`` when given) as JSON."""
    keys = [*DEFAULTS, *([PLATFORM_HASH] if options.get(PLATFORM_HASH) else [])]
    return f"/* {TAG} {json.dumps({k: options[k] for k in keys}, sort_keys=True)} */\n"


def stamp(files: dict, options: dict) -> dict:
    """``files`` (name -> C text) with the fingerprint line first in each ``.c`` and ``.h`` file."""
    line = fingerprint_line(options)
    return {n: (line + t if n.endswith((".c", ".h")) else t) for n, t in files.items()}


def read_fingerprint(path) -> tuple[dict, Path] | None:
    """``(options, file it was read from)`` recorded in ``path`` or in the ``sd_firmware.h`` next to it, or
    None when neither carries one (a hand-written module). ``options`` has ``DEFAULTS``' keys and
    ``PLATFORM_HASH`` (None in a module generated before it was recorded)."""
    p = Path(path)
    for f in (p, p.with_name("sd_firmware.h")):
        try:
            with f.open("rb") as fh:
                head = fh.read(HEAD_BYTES).decode("utf-8", "replace")
        except OSError:
            continue
        m = _LINE.search(head)
        if m:
            try:
                rec = json.loads(m.group(1))
            except json.JSONDecodeError:
                continue
            if isinstance(rec, dict):
                return {**{k: rec.get(k, v) for k, v in DEFAULTS.items()}, PLATFORM_HASH: rec.get(PLATFORM_HASH)}, f
    return None


def resolve_options(given: dict, path) -> tuple[dict, str | None]:
    """The options ``check`` uses: each given one (not None) as given, the others from the fingerprint of
    ``path`` (else ``DEFAULTS``); ``(options, mismatch)`` where ``mismatch`` names the first given option
    that differs from the recorded one (``name=given here, recorded in FILE``), else None."""
    rec = read_fingerprint(path)
    recorded, where = rec if rec else ({}, None)
    out = {}
    for k, default in DEFAULTS.items():
        g = given.get(k)
        out[k] = g if g is not None else recorded.get(k, default)
        if g is not None and k in recorded and not _same(g, recorded[k]):
            return out, f"{k}={g} here, {recorded[k]} in {where}"
    return out, None


def _same(a, b) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return float(a) == float(b)
    return a == b


# A module generated from a Python ``Trajectory`` (no name ``check`` can look up) records, as its ``trajectory``
# option, ``{"name", "design_poses": DESIGN_POSES, "sha256"}``; the poses the gains were designed over are in
# that file beside the C, and the hash (of their float64 bytes) in every fingerprint ties the file to the module.
DESIGN_POSES = "sd_design_poses.json"


def poses_hash(poses) -> str:
    """The sha256 of ``(n, 6)`` design poses (SI) as little-endian float64 bytes."""
    return hashlib.sha256(np.ascontiguousarray(poses, dtype="<f8").tobytes()).hexdigest()


def motion_record(name: str, poses) -> tuple[dict, str]:
    """``(the trajectory option recorded, the DESIGN_POSES file's text)`` of a module whose gains were designed
    over ``poses`` ``(n, 6)`` (SI) of the Python trajectory ``name`` (JSON keeps every float bit for bit)."""
    text = json.dumps({"trajectory": name, "poses": np.asarray(poses, dtype=float).tolist()}) + "\n"
    return {"name": name, "design_poses": DESIGN_POSES, "sha256": poses_hash(poses)}, text


def recorded_design_poses(record: dict, where: Path) -> np.ndarray:
    """The design poses ``(n, 6)`` (SI) a ``motion_record`` names, read from beside ``where`` (the file the
    fingerprint was read from) and checked against its hash; ``FirmwareError`` naming the file if it is missing,
    unreadable or not the one generated with the module."""
    path = Path(where).with_name(str(record.get("design_poses", DESIGN_POSES)))
    try:
        poses = np.asarray(json.loads(path.read_text(encoding="utf-8"))["poses"], dtype=float)
        ok = poses.ndim == 2 and poses.shape[1:] == (6,) and poses_hash(poses) == record.get("sha256")
    except (OSError, ValueError, KeyError, TypeError) as e:
        reason = e.strerror if isinstance(e, OSError) and e.strerror else type(e).__name__
        raise FirmwareError(
            FirmwareError.DESIGN_POSES.format(path=path, name=record.get("name"), where=where, reason=reason)
        ) from None
    if not ok:
        raise FirmwareError(
            FirmwareError.DESIGN_POSES.format(
                path=path, name=record.get("name"), where=where, reason="not the poses it was generated with"
            )
        )
    return poses
