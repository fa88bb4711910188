"""What a report studies: the built-in presets (the default) or a user's machine, as one small typed ``Subject``.

``--platform FILE|NAME`` fills a ``Subject`` with the platform alone (``from_platform``); ``--machine FILE`` fills
it from a machine file read by ``spec.load_machine`` (``from_machine_file``: the platform with its payload, and
the loop's fixed-point ``firmware:`` format, ``motions:`` and a ``requirements:`` file where the file gives them). Each analysis says whether it
applies to a user's machine and what it needs of it with two literals read from its source
(``report.metadata``): ``NEEDS = ("plate", "legs.max_force", ...)`` (see ``NEEDS``), or ``PRESET_ONLY = "why"``
for a section that reproduces the presets' published numbers. A section that does not apply is shown with a
"not applicable" line saying what it needs that the file does not give (``not_applicable``).
"""

from __future__ import annotations

import hashlib
import html
import pickle
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from stewart_drake.control.gains import ControllerConfig, counts_per_lsb
from stewart_drake.core.geometry import (
    PRESETS,
    Platform,
    PlatformConfig,
    load_platform,
    load_yaml_config,
    preset_path,
)
from stewart_drake.core.trajectory import TRAJECTORIES, Trajectory, fit_trajectory, get_trajectory
from stewart_drake.errors import GainError, ReportSubjectError
from stewart_drake.fixedpoint.generic import QFormat
from stewart_drake.spec import Machine, load_machine

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
        machine: the ``Machine`` as read (its controller, sensors and actuators), None for ``--platform`` (a
            machine with the defaults: ``machine_of``).
    """

    name: str
    platform: Platform
    source: str
    given: frozenset = frozenset()
    ik_format: QFormat | None = None
    motions: tuple = ()
    requirements: str | None = None
    files: tuple = field(default=())
    machine: Machine | None = None

    def key(self) -> str:
        """SHA-256 (hex) of the declared inputs: the subject as read (its pickled fields, every number exact) and
        each file's path and content."""
        fields = (self.name, self.platform, self.ik_format, self.motions, self.machine)
        h = hashlib.sha256(pickle.dumps(fields, protocol=4))
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


def _mapping_keys(node, prefix: str = "") -> set:
    """The dotted keys of a YAML mapping, each prefix included (list items dropped)."""
    out = set()
    if isinstance(node, dict):
        for k, v in node.items():
            key = f"{prefix}{k}"
            out |= {key} | _mapping_keys(v, key + ".")
    return out


def _as_written(value, machine_file) -> str:
    """A path the machine file named, as written there (relative to the file's folder), for messages."""
    try:
        return str(Path(value).resolve().relative_to(Path(machine_file).resolve().parent))
    except (ValueError, TypeError):
        return str(value)


def from_machine_file(path) -> Subject:
    """The subject of ``--machine FILE`` (or a ``Machine``): read by ``spec.load_machine`` (errors name the file,
    line and spec path); the report uses its platform with the payload on the plate, the loop's fixed-point
    format when the file gives ``firmware:``, its ``motions:`` and ``requirements:``."""
    if isinstance(path, Machine):
        machine, shown, raw = path, path.platform.name, None
    else:
        shown = str(path)
        machine = load_machine(path)
        raw = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    if raw is None:  # a Machine object gives every field
        given = {"legs.max_force", "firmware", "motions"}
        given |= {"legs.stiffness"} if machine.platform.legs.stiffness is not None else set()
        given |= {"plate.mass"} if machine.platform.mass > 0 else set()
    else:
        inline = raw.get("platform", raw)
        if isinstance(inline, str):  # the platform by name or path: the keys its own file gives
            src = machine.platform_source or inline
            inline = None
            given = set(_given_keys(_keys_of(preset_path(src) if src in PRESETS else Path(src))))
        else:
            given = _mapping_keys(inline)
        given |= {k for k in ("firmware", "motions") if k in raw}
    platform = machine.loaded_platform
    fmt = machine.firmware.qformat() if "firmware" in given else None
    if fmt is not None:
        try:  # the loop's sensor counts a whole number of its counts per LSB
            counts_per_lsb(ControllerConfig(ik_format=fmt))
        except GainError as e:
            raise ReportSubjectError(
                ReportSubjectError.FIELD.format(path=shown, field="firmware.length_lsb", problem=e)
            ) from None
    motions, files = [], [] if raw is None else [str(Path(path).resolve())]
    for i, m in enumerate(machine.motions if "motions" in given else (), 1):
        if isinstance(m, Trajectory) or m in TRAJECTORY_NAMES:
            motions.append(m)
        elif str(m).endswith((".csv", ".stw")) and Path(m).is_file():
            motions.append(str(Path(m).resolve()))
            files.append(str(Path(m).resolve()))
            if str(m).endswith(".stw"):  # a program's errors are the file's: its file, line and column, now
                Trajectory.from_program(m, platform)
        else:
            raise ReportSubjectError(ReportSubjectError.MOTION.format(path=shown, item=i, value=_as_written(m, path)))
    requirements = None
    if machine.requirements:
        r = Path(machine.requirements)
        if not r.is_file():
            raise ReportSubjectError(
                ReportSubjectError.FIELD.format(
                    path=shown,
                    field="requirements",
                    problem=f"{_as_written(machine.requirements, path)!r} is not a file",
                )
            )
        requirements = str(r.resolve())
        files.append(requirements)
    return Subject(
        platform.name, platform, shown, frozenset(given), fmt, tuple(motions), requirements, tuple(files), machine
    )


def machine_of(subject: Subject) -> Machine:
    """The machine the report runs for ``subject``: the machine file's, or its platform with every other section at
    the defaults (``--platform``)."""
    if subject.machine is not None:
        return subject.machine
    return load_machine(subject.platform)


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
