"""The options a firmware module was generated with, recorded in its files (a fingerprint) and read back by
``firmware check``: a check with other options compares the C against another emulation and reported
hundreds of differences with no hint. ``check`` takes the recorded options by default and names an option
given on its command line that differs from the recorded one."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

from stewart_drake.core.geometry import Platform
from stewart_drake.core.platform_file import platform_yaml

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


def resolve_options(given: dict, path, option_names: dict) -> tuple[dict, str | None]:
    """The options ``check`` uses: each given one (not None) as given, the others from the fingerprint of
    ``path`` (else ``DEFAULTS``); ``(options, mismatch)`` where ``mismatch`` names the first given option
    that differs from the recorded one (``option_names``: key -> ``--option``), else None."""
    rec = read_fingerprint(path)
    recorded, where = rec if rec else ({}, None)
    out = {}
    for k, default in DEFAULTS.items():
        g = given.get(k)
        out[k] = g if g is not None else recorded.get(k, default)
        if g is not None and k in recorded and not _same(g, recorded[k]):
            return out, f"{option_names[k]} {g} here, {recorded[k]} in {where}"
    return out, None


def _same(a, b) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return float(a) == float(b)
    return a == b
