"""What a report studies: the built-in presets (the default) or a user's machine, as one small typed ``Subject``.

``--platform FILE|NAME`` fills a ``Subject`` with the platform alone (``from_platform``); ``--machine FILE`` fills
it from a machine file (``from_machine_file``: the platform's keys, and optionally the loop's fixed-point
``firmware:`` format, ``motions:``, a ``payload:`` and a ``requirements:`` file). Each analysis says whether it
applies to a user's machine and what it needs of it with two literals read from its source
(``report.metadata``): ``NEEDS = ("plate", "legs.max_force", ...)`` (see ``NEEDS``), or ``PRESET_ONLY = "why"``
for a section that reproduces the presets' published numbers. A section that does not apply is shown with a
"not applicable" line saying what it needs that the file does not give (``not_applicable``).
"""

from __future__ import annotations

import hashlib
import html
import math
import pickle
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from stewart_drake.control.gains import ControllerConfig, counts_per_lsb
from stewart_drake.core.geometry import (
    PLATFORM_RULES,
    PLATFORM_SHAPES,
    PRESETS,
    Platform,
    PlatformConfig,
    check_home,
    check_length_unit,
    check_name,
    check_shared_base,
    load_platform,
    load_yaml_config,
    platform_from_config,
    preset_path,
)
from stewart_drake.core.trajectory import TRAJECTORIES, Trajectory, fit_trajectory, get_trajectory
from stewart_drake.core.yamlio import check_rules
from stewart_drake.design.payload import with_payload
from stewart_drake.errors import FixedPointError, GainError, GeometryError, ReportSubjectError
from stewart_drake.fixedpoint.generic import QFormat

# What an analysis may need of a user's machine (``NEEDS``), and how the report says that the file lacks it.
NEEDS = {
    "plate": "the plate's mass properties (plate: mass, com, inertia)",
    "legs.max_force": "the actuators' force limit (legs.max_force)",
    "legs.stiffness": "the legs' axial stiffness (legs.stiffness)",
    "requirements": "a requirements file (requirements: in a machine file)",
    "motions": "a motion (motions: in a machine file)",
    "firmware": "the loop's fixed-point format (firmware: word_bits, length_lsb, trig in a machine file)",
}
TRAJECTORY_NAMES = ("seed", "rotating")


@dataclass(frozen=True)
class Subject:
    """A user's machine as the report studies it.

    Attributes:
        name: the machine's name (the report's title names it).
        platform: the platform, the payload merged into its plate (SI).
        source: the file (or preset name) as the user wrote it.
        given: the file's keys that were given, dotted (``plate.mass``, ``legs.max_force``, ``firmware``, ...).
        ik_format: the loop's fixed-point IK format (``firmware:``), None: not given (the DSP's default).
        motions: ``seed``, ``rotating`` or paths of ``.csv`` and ``.stw`` files, as resolved paths.
        requirements: the requirements file's resolved path, or None.
        files: every file the subject was read from (the machine or platform file, its requirements and motion
            files): the report's declared inputs, whose content keys its cached sections (``key``).
    """

    name: str
    platform: Platform
    source: str
    given: frozenset = frozenset()
    ik_format: QFormat | None = None
    motions: tuple = ()
    requirements: str | None = None
    files: tuple = field(default=())

    def key(self) -> str:
        """SHA-256 (hex) of the declared inputs: the subject as read (its pickled fields, every number exact) and
        each file's path and content."""
        h = hashlib.sha256(pickle.dumps((self.name, self.platform, self.ik_format, self.motions), protocol=4))
        for f in self.files:
            h.update(f"{f}\0".encode() + hashlib.sha256(Path(f).read_bytes()).digest())
        return h.hexdigest()

    def missing(self, needs) -> list[str]:
        """The descriptions (``NEEDS``) of what ``needs`` asks that the file does not give."""
        have = set(self.given) - {"plate"}  # a ``plate:`` key without a mass gives no plate
        have |= {"motions"} if self.motions else set()
        have |= {"requirements"} if self.requirements else set()
        have |= {"firmware"} if self.ik_format is not None else set()
        have |= {"plate"} if self.platform.mass > 0 else set()  # its plate or its payload gave the plate a mass
        return [NEEDS[n] for n in needs if n not in have]


def not_applicable(analysis, subject: Subject) -> str:
    """Why ``analysis`` does not apply to ``subject`` ('' when it does): a preset-only section, or what it needs
    that the file does not give."""
    if analysis.needs is None:
        return analysis.preset_only or "this section studies the built-in presets only"
    lacking = subject.missing(analysis.needs)
    if lacking:
        return f"needs {', '.join(lacking)}, which {subject.source} does not give"
    return ""


def not_applicable_html(subject: Subject, reason: str) -> str:
    """The visible line of a section that does not apply."""
    return f'<p class="na">Not applicable to {html.escape(subject.name)}: {html.escape(reason)}.</p>'


def mark_not_applicable(section, subject: Subject, reason: str) -> None:
    """Say in ``section`` (a whole section found inapplicable while it is built) why it does not apply."""
    section.html(not_applicable_html(subject, reason))
    section.headline(f"not applicable: {reason}")


def _given_keys(where: dict) -> frozenset:
    """The dotted keys a file gave (``where``'s field paths, list items dropped), each prefix included."""
    out = set()
    for path in where:
        keys = [p for p in path if isinstance(p, str)]
        out |= {".".join(keys[: k + 1]) for k in range(len(keys))}
    return frozenset(out)


def from_platform(name_or_path) -> Subject:
    """The subject of ``--platform FILE|NAME``: a preset, a platform file or a ``Platform``, alone (a ``Platform``
    gives every field)."""
    if isinstance(name_or_path, Platform):
        p = name_or_path
        given = {"legs.max_force"}
        given |= {"legs.stiffness"} if p.legs.stiffness is not None else set()
        return Subject(p.name, p, p.name, frozenset(given))
    s = str(name_or_path)
    path = preset_path(s) if s in PRESETS else Path(s)
    if s in PRESETS:
        return Subject(s, load_platform(s), s, _given_keys(_keys_of(path)), files=())
    platform = load_platform(s)
    return Subject(platform.name, platform, s, _given_keys(_keys_of(path)), files=(str(path.resolve()),))


def _keys_of(path: Path) -> dict:
    """The field paths a platform file gives (``load_yaml_config``'s ``where``)."""
    where: dict = {}
    load_yaml_config(path, PlatformConfig, "platform", lambda cfg, w: where.update(w))
    return where


# ------------------------------------------------------------------------------------------------------------
# The machine file: a stand-in for the machine spec's loader, in one place.


@dataclass
class FirmwareFields:
    """``firmware:`` of a machine file: the loop's fixed-point IK format (``length_lsb`` in the file's unit)."""

    word_bits: int = 16
    length_lsb: float = 0.0  # 0: the DSP's 1 mm
    trig: str = ""  # "": tfr16 for 16-bit words, exact otherwise


@dataclass
class PayloadFields:
    """``payload:`` of a machine file: a point mass (kg) fixed to the plate at ``position`` (file unit, in T)."""

    mass: float = 0.0
    position: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class MachineFile(PlatformConfig):
    """A machine file as this report reads it: a platform file's keys plus ``firmware``, ``motions`` (``seed``,
    ``rotating``, or ``.csv`` and ``.stw`` paths relative to the file), ``payload`` and ``requirements`` (a path)."""

    firmware: FirmwareFields | None = None
    motions: list[str] = field(default_factory=list)
    payload: PayloadFields | None = None
    requirements: str = ""


def _check_payload(p: PayloadFields, shown: str, unit: str) -> None:
    """A physical payload: a finite mass >= 0 kg at three finite coordinates on or above the plate (z >= 0)."""

    def bad(field_, problem):
        return ReportSubjectError(ReportSubjectError.FIELD.format(path=shown, field=field_, problem=problem))

    if not (math.isfinite(p.mass) and p.mass >= 0):
        raise bad("payload.mass", f"must be a finite number >= 0 kg, got {p.mass:g}")
    if len(p.position) != 3 or not all(math.isfinite(v) for v in p.position):
        raise bad("payload.position", f"must be three finite numbers [x, y, z] in {unit}, got {p.position}")
    if p.position[2] < 0:
        raise bad(
            "payload.position",
            f"z = {p.position[2]:g} {unit} is below the plate (the plate frame's z >= 0 holds the plate and its load)",
        )


def from_machine_file(path) -> Subject:
    """The subject of ``--machine FILE``. Errors name the file and the field (``YamlError``,
    ``ReportSubjectError``).

    This reads the parts of a machine file the report uses; the machine spec's ``load_machine`` replaces it."""
    shown = str(path)
    where: dict = {}

    def check(cfg, w):  # a platform file's checks (``core.geometry.load_platform_yaml``'s), on its keys
        check_name(cfg, w, shown)
        k = check_length_unit(cfg, w, shown)
        check_rules(w, PLATFORM_RULES, PLATFORM_SHAPES, cfg, shown, k, cfg.length_unit)
        check_shared_base(cfg, w, shown, k)
        where.update(w)

    cfg = load_yaml_config(path, MachineFile, "machine", check)
    try:
        platform = platform_from_config(cfg)
    except GeometryError as e:
        raise GeometryError(GeometryError.IN_FILE.format(path=shown, problem=e)) from None
    check_home(platform)
    k = 1e-3 if cfg.length_unit == "mm" else 1.0
    if cfg.payload is not None:
        _check_payload(cfg.payload, shown, cfg.length_unit)
        platform = with_payload(platform, cfg.payload.mass, [v * k for v in cfg.payload.position])
    fmt = None
    if cfg.firmware is not None:
        f = cfg.firmware
        trig = f.trig or ("tfr16" if f.word_bits == 16 else "exact")
        try:
            fmt = QFormat(f.word_bits, f.length_lsb * k if f.length_lsb else 1e-3, trig)
        except FixedPointError as e:
            raise ReportSubjectError(ReportSubjectError.FIELD.format(path=shown, field="firmware", problem=e)) from None
        try:  # the loop's sensor counts a whole number of its counts per LSB
            counts_per_lsb(ControllerConfig(ik_format=fmt))
        except GainError as e:
            raise ReportSubjectError(
                ReportSubjectError.FIELD.format(path=shown, field="firmware.length_lsb", problem=e)
            ) from None
    folder = Path(path).resolve().parent
    motions, files = [], [str(Path(path).resolve())]
    for i, m in enumerate(cfg.motions, 1):
        if m in TRAJECTORY_NAMES:
            motions.append(m)
        elif m.endswith((".csv", ".stw")) and (folder / m).is_file():
            motions.append(str(folder / m))
            files.append(str(folder / m))
            if m.endswith(".stw"):  # a program's errors are the file's: its file, line and column, now
                Trajectory.from_program(folder / m, platform)
        else:
            raise ReportSubjectError(ReportSubjectError.MOTION.format(path=shown, item=i, value=m))
    requirements = None
    if cfg.requirements:
        r = folder / cfg.requirements
        if not r.is_file():
            raise ReportSubjectError(
                ReportSubjectError.FIELD.format(
                    path=shown, field="requirements", problem=f"{cfg.requirements!r} is not a file"
                )
            )
        requirements = str(r)
        files.append(requirements)
    return Subject(platform.name, platform, shown, _given_keys(where), fmt, tuple(motions), requirements, tuple(files))


def subject_trajectories(subject: Subject) -> list[Trajectory]:
    """The motions the sections run on ``subject``: its ``motions`` (``seed`` and ``rotating`` fitted to its home
    height and stroke, CSV files as written, metres and radians, ``.stw`` programs run on its platform), or when it
    gives none, both fitted ones."""
    out = []
    for m in subject.motions or TRAJECTORY_NAMES:
        if m in TRAJECTORY_NAMES:
            out.append(fit_trajectory(TRAJECTORIES[m], subject.platform))
        elif m.endswith(".stw"):
            out.append(Trajectory.from_program(m, subject.platform))
        else:
            out.append(get_trajectory(m))
    return out


def motion_rates(traj: Trajectory, t, h: float = 1e-4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, q̇, q̈)``, each ``(n, 6)`` SI, of ``traj`` at times ``t`` (n,) s by five-point central differences of
    its poses (step ``h`` s; truncation O(h⁴), rounding ~1e-16/h² relative): any motion, fitted or read."""
    t = np.asarray(t, dtype=float)
    q = [traj.pose(t + k * h) for k in (-2, -1, 0, 1, 2)]
    qd = (q[0] - 8 * q[1] + 8 * q[3] - q[4]) / (12 * h)
    qdd = (-q[0] + 16 * q[1] - 30 * q[2] + 16 * q[3] - q[4]) / (12 * h * h)
    return q[2], qd, qdd
