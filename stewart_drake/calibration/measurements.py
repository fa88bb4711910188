"""Calibration measurements: the three CSV kinds, read with every bad row named by its line, and written.

Every file has a header row naming its columns (any order; an optional ``w`` column weighs a pose):

- ``pose``: ``l1..l6`` (the legs' sensor readings) and ``px,py,pz,a,b,g`` (the plate's measured pose in the
  base frame, as ``ik --pose`` takes it: rotation centre and angles in the platform file's convention);
- ``points``: ``l1..l6`` and targets ``tK_x,tK_y,tK_z`` (K = 1, 2, ...: points fixed on the plate, measured
  in the base frame; their plate-frame positions are identified too);
- ``inclinometer``: ``l1..l6`` and ``tilt_x,tilt_y`` (the plate's tilt: for R_BT = Rz(γ)·Ry(β)·Rx(α),
  tilt_x = α and tilt_y = β, whatever the yaw γ; see ``model.tilts``).

Lengths are in ``length_unit`` (m or mm), angles in ``angle_unit`` (rad, deg or pi); inside, SI.
"""

from __future__ import annotations

import csv
import hashlib
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from stewart_drake.core.csvio import is_number
from stewart_drake.core.distinct import distinct_rows
from stewart_drake.core.geometry import Platform
from stewart_drake.core.rotations import angle_scale, length_scale
from stewart_drake.core.sanity import FAR_FACTOR, platform_size
from stewart_drake.core.unit_hint import other_unit_hint
from stewart_drake.errors import CalibrationError
from stewart_drake.system.input_stream import read_input

TYPES = ("pose", "points", "inclinometer")
READINGS = tuple(f"l{i}" for i in range(1, 7))
POSE = ("px", "py", "pz", "a", "b", "g")
TILTS = ("tilt_x", "tilt_y")
MAX_ROWS = 100_000
MAX_BYTES = MAX_ROWS * 1000  # a row: a kind, up to 8 targets' readings, weights (~200 bytes)
MAX_TARGETS = 8
_TARGET = re.compile(r"^t(\d+)_([xyz])$")


@dataclass(frozen=True, eq=False)
class Measurements:
    """One measurement set in SI units.

    kind      ``pose`` | ``points`` | ``inclinometer``
    readings  ``(n, 6)`` sensor readings, m
    poses     ``(n, 6)`` measured poses (m, rad, ``convention``), ``pose`` kind; else None
    targets   ``(n, K, 3)`` measured target positions in B, m, ``points`` kind; else None
    tilts     ``(n, 2)`` tilt_x, tilt_y, rad, ``inclinometer`` kind; else None
    weights   ``(n,)`` > 0 (1 when the file has no ``w``)
    lines     ``(n,)`` the file line of each row (counted from 1)
    """

    kind: str
    readings: np.ndarray
    poses: np.ndarray | None = None
    targets: np.ndarray | None = None
    tilts: np.ndarray | None = None
    weights: np.ndarray = field(default_factory=lambda: np.ones(0))
    lines: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    source: str = ""
    sha256: str = ""

    def __len__(self) -> int:
        return len(self.readings)

    @property
    def n_targets(self) -> int:
        return 0 if self.targets is None else self.targets.shape[1]

    def subset(self, rows) -> Measurements:
        """The measurements of ``rows`` (indices or a mask), same file and hash."""
        rows = np.asarray(rows)

        def pick(a):
            return None if a is None else a[rows]

        return Measurements(
            self.kind,
            self.readings[rows],
            pick(self.poses),
            pick(self.targets),
            pick(self.tilts),
            self.weights[rows],
            self.lines[rows],
            self.source,
            self.sha256,
        )

    def values(self) -> np.ndarray:
        """``(n, k)`` the measured numbers of each row: readings, then the measured pose, targets or tilts (SI);
        not the weight, which says how much a row counts, not what was measured."""
        parts = [
            a.reshape(len(self), -1) for a in (self.readings, self.poses, self.targets, self.tilts) if a is not None
        ]
        return np.concatenate(parts, axis=1)

    def without_copies(self) -> tuple[Measurements, list[tuple[int, int]]]:
        """``(measurements, copies)``: each row whose ``values`` repeat an earlier row's bit for bit kept once (the
        first, with its weight), and ``[(line, line it repeats), ...]`` for the rows dropped. A copy is not a second
        measurement: its noise is the same draw, so counting it would shrink σ by √2 per doubling and pass a single
        pose for many."""
        rows, inverse = distinct_rows(self.values())
        first = np.full(len(rows), len(self))
        np.minimum.at(first, inverse, np.arange(len(self)))
        keep = first[inverse] == np.arange(len(self))
        if keep.all():
            return self, []
        dropped = np.flatnonzero(~keep)
        copies = [(int(self.lines[i]), int(self.lines[first[inverse[i]]])) for i in dropped]
        return self.subset(keep), copies

    def distinct_poses(self, tolerance: float) -> int:
        """The number of distinct poses: rows whose six readings all lie within ``tolerance`` (m) of another's
        are one pose (transitively), however often it was measured."""
        pairs = cKDTree(self.readings).query_pairs(tolerance, p=np.inf, output_type="ndarray")
        n = len(self)
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        return int(connected_components(graph, directed=False)[0])


def columns_of(kind: str, n_targets: int = 1) -> tuple[str, ...]:
    """The columns of a ``kind`` file, in the order ``write_measurements`` writes them."""
    if kind == "pose":
        return READINGS + POSE
    if kind == "points":
        return READINGS + tuple(f"t{k}_{a}" for k in range(1, n_targets + 1) for a in "xyz")
    return READINGS + TILTS


def _kind_of(header: list[str]) -> str | None:
    if "px" in header:
        return "pose"
    if any(_TARGET.match(h) for h in header):
        return "points"
    if "tilt_x" in header:
        return "inclinometer"
    return None


def read_measurements(
    path,
    platform: Platform,
    kind: str | None = None,
    length_unit: str = "m",
    angle_unit: str = "rad",
) -> Measurements:
    """Read and check one measurement CSV (see the module docstring): every value finite, weights > 0,
    every reading giving a length within the platform's stroke (a mistaken unit is named), angles within
    ±π rad. ``kind`` None: taken from the header. Raises ``CalibrationError`` naming file, line and column."""
    f = Path(path)
    shown = str(path)
    if not f.exists():
        raise CalibrationError(CalibrationError.MISSING.format(path=shown))
    if f.is_dir():
        raise CalibrationError(CalibrationError.NOT_A_FILE.format(path=shown))
    # read once as a stream (a FIFO works), bounded: MAX_ROWS rows of a few hundred bytes
    data = read_input(path, kind="measurements", limit=MAX_BYTES)
    digest = hashlib.sha256(data).hexdigest()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise CalibrationError(CalibrationError.NOT_TEXT.format(path=shown, offset=e.start)) from None
    text_lines = text.splitlines()
    # the header alone is parsed first: a bad one is refused before the body is (seconds for a large file)
    head_line, head = next(
        (
            (i + 1, r)
            for i, line in enumerate(text_lines)
            for r in csv.reader([line])
            if r and any(c.strip() for c in r)
        ),
        (0, None),
    )
    if head is None:
        raise CalibrationError(CalibrationError.EMPTY.format(path=shown))
    header = [h.strip() for h in head]
    found = _kind_of(header)
    if kind is None:
        kind = found or "pose"
    need = ",".join(columns_of(kind, 1)).replace("t1_x,t1_y,t1_z", "tK_x,tK_y,tK_z")
    if all(is_number(h) for h in header):
        raise CalibrationError(CalibrationError.NO_HEADER.format(path=shown, need=need, row=",".join(head)[:80]))
    if found is not None and found != kind:
        raise CalibrationError(
            CalibrationError.TYPE.format(path=shown, kind=kind, found=found, header=",".join(header))
        )
    n_targets = 0
    if kind == "points":
        tk = [h for h in header if _TARGET.match(h)]
        n_targets = len(tk) // 3
        expect = [f"t{k}_{a}" for k in range(1, n_targets + 1) for a in "xyz"]
        if not tk or sorted(tk) != sorted(expect) or n_targets > MAX_TARGETS:
            raise CalibrationError(CalibrationError.TARGETS.format(path=shown, names=",".join(tk) or "none"))
    wanted = columns_of(kind, n_targets)
    for h in header:
        if h not in wanted and h != "w":
            raise CalibrationError(
                CalibrationError.UNKNOWN_COLUMN.format(path=shown, line=head_line, name=h, kind=kind, need=need)
            )
    missing = [c for c in wanted if c not in header]
    if missing or len(set(header)) != len(header):
        raise CalibrationError(
            CalibrationError.COLUMNS.format(
                path=shown,
                line=head_line,
                kind=kind,
                need=need,
                missing=",".join(missing) or "(a column is repeated)",
                header=",".join(header),
            )
        )
    body = [
        (head_line + 1 + i, r)
        for i, r in enumerate(csv.reader(text_lines[head_line:]))
        if r and any(c.strip() for c in r)
    ]
    if len(body) > MAX_ROWS:
        raise CalibrationError(CalibrationError.TOO_MANY.format(path=shown, limit=MAX_ROWS))
    if not body:
        raise CalibrationError(CalibrationError.EMPTY.format(path=shown))
    values = np.empty((len(body), len(header)))
    for r, (line, row) in enumerate(body):
        if len(row) != len(header):
            raise CalibrationError(
                CalibrationError.WIDTH.format(path=shown, line=line, expected=len(header), got=len(row))
            )
        for c, cell in enumerate(row):
            try:
                v = float(cell)
            except ValueError:
                raise CalibrationError(
                    CalibrationError.NOT_NUMBER.format(path=shown, line=line, column=header[c], value=cell[:40])
                ) from None
            if not math.isfinite(v):
                raise CalibrationError(
                    CalibrationError.NOT_FINITE.format(path=shown, line=line, column=header[c], value=cell[:40])
                )
            values[r, c] = v
    lines = np.array([line for line, _ in body])
    col = {h: values[:, i] for i, h in enumerate(header)}
    k, a = length_scale(length_unit), angle_scale(angle_unit)
    readings = np.stack([col[c] for c in READINGS], axis=1) * k
    _check_readings(readings, platform, lines, shown, length_unit)
    weights = col.get("w", np.ones(len(body)))
    bad = np.flatnonzero(~(weights > 0))
    if bad.size:
        cell = body[bad[0]][1][header.index("w")].strip()
        raise CalibrationError(CalibrationError.WEIGHT.format(path=shown, line=lines[bad[0]], value=cell))
    poses = targets = tilts = None
    if kind == "pose":
        poses = np.stack([col[c] for c in POSE], axis=1)
        _check_angles(poses[:, 3:], POSE[3:], lines, shown, angle_unit)
        poses = np.concatenate([poses[:, :3] * k, poses[:, 3:] * a], axis=1)
        # a unit mistake puts positions far outside the platform (the sanity rule); poses merely outside this
        # platform's workspace are measurements of another machine, which the fit's verdict reports
        far = np.linalg.norm(poses[:, :3], axis=1) > FAR_FACTOR * platform_size(platform)
        hint = other_unit_hint(platform, poses, length_unit, angle_unit) if far.any() else ""
        if hint:
            raise CalibrationError(CalibrationError.POSE_UNIT.format(path=shown, hint=hint))
    elif kind == "points":
        targets = np.stack([col[c] for c in columns_of(kind, n_targets)[6:]], axis=1).reshape(-1, n_targets, 3) * k
    else:
        tilts = np.stack([col[c] for c in TILTS], axis=1)
        _check_angles(tilts, TILTS, lines, shown, angle_unit)
        tilts = tilts * a
    return Measurements(kind, readings, poses, targets, tilts, np.asarray(weights, float), lines, shown, digest)


def _check_readings(readings, platform: Platform, lines, shown: str, unit: str) -> None:
    """Each reading + the platform's offset within the stroke (a 1 % margin: a built machine's joints
    sit off the drawing), else the first bad one named, with a unit hint when another unit fits."""
    L = platform.lengths_from_readings(readings)
    span = platform.L_max - platform.L_min
    lo, hi = platform.L_min - 0.05 * span, platform.L_max + 0.05 * span
    bad = np.argwhere((L < lo) | (L > hi))
    if not bad.size:
        return
    r, leg = bad[0]
    hint = ""
    for guess, factor in (("mm", 1e-3), ("m", 1e3)):
        if guess != unit and np.all(
            (platform.lengths_from_readings(readings * factor) >= lo)
            & (platform.lengths_from_readings(readings * factor) <= hi)
        ):
            hint = CalibrationError.UNIT_HINT.format(guess=guess)
    shown_value = readings[r, leg] / length_scale(unit)
    raise CalibrationError(
        CalibrationError.STROKE.format(
            path=shown,
            line=lines[r],
            leg=leg + 1,
            value=f"{shown_value:g}",
            unit=unit,
            length=L[r, leg],
            lmin=platform.L_min,
            lmax=platform.L_max,
            name=platform.name,
            hint=hint,
        )
    )


def _check_angles(angles, names, lines, shown: str, unit: str) -> None:
    limit = math.pi / angle_scale(unit)
    bad = np.argwhere(np.abs(angles) > limit)
    if bad.size:
        r, c = bad[0]
        hint = CalibrationError.ANGLE_HINT if unit == "rad" and np.all(np.abs(angles) <= 180) else ""
        raise CalibrationError(
            CalibrationError.ANGLE.format(
                path=shown,
                line=lines[r],
                column=names[c],
                value=f"{angles[r, c]:g}",
                unit=unit,
                limit=f"{limit:g}",
                hint=hint,
            )
        )


def measurements_csv(m: Measurements) -> str:
    """The CSV text of ``m`` (SI units: m, rad), header first, full precision, with its ``w`` column."""
    cols = columns_of(m.kind, m.n_targets) + ("w",)
    if m.kind == "pose":
        data = np.concatenate([m.readings, m.poses], axis=1)
    elif m.kind == "points":
        data = np.concatenate([m.readings, m.targets.reshape(len(m), -1)], axis=1)
    else:
        data = np.concatenate([m.readings, m.tilts], axis=1)
    data = np.concatenate([data, m.weights[:, None]], axis=1)
    return ",".join(cols) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in data)
