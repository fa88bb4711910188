"""``stewart-drake init``: print a commented, valid starting file (``--platform-template``,
``--machine-template``, ``--envelope-template`` or ``--requirements-template``)."""

from __future__ import annotations

import sys
from importlib import resources

TEMPLATES = ("utn", "radial", "explicit")


def register(sub) -> None:
    p = sub.add_parser(
        "init",
        help="print a commented platform file template to start from (stewart-drake init --platform-template radial > my.yaml)",
    )
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument(
        "--platform-template",
        choices=TEMPLATES,
        help="utn: the UTN 3-6 family; radial: anchors on two circles; explicit: anchor by anchor",
    )
    which.add_argument(
        "--machine-template",
        action="store_true",
        help="a machine file for `simulate --machine`: a radial platform with every other section (payload, "
        "controller, firmware format, sensors, actuators, motions, run) at its default, with units",
    )
    which.add_argument(
        "--envelope-template",
        action="store_true",
        help="a duty envelope for `size --envelope` (poses + velocity and acceleration bounds), "
        "made for the radial platform template",
    )
    which.add_argument(
        "--requirements-template",
        action="store_true",
        help="a requirements file for stewart-drake optimize (design synthesis)",
    )
    p.set_defaults(func=run)


def template_text(kind: str) -> str:
    """The text of the platform template ``kind`` (one of ``TEMPLATES``), or of the envelope or machine
    template when ``kind`` is ``"envelope"`` or ``"machine"``."""
    name = {"envelope": "envelope.yaml", "machine": "machine.yaml"}.get(kind, f"platform-{kind}.yaml")
    return (resources.files("stewart_drake") / "templates" / name).read_text(encoding="utf-8")


def requirements_template_text() -> str:
    """The text of the requirements template (``stewart-drake optimize``)."""
    return (resources.files("stewart_drake") / "templates" / "requirements.yaml").read_text(encoding="utf-8")


def run(args) -> int:
    if args.requirements_template:
        sys.stdout.write(requirements_template_text())
        return 0
    if args.machine_template:
        sys.stdout.write(template_text("machine"))
        return 0
    sys.stdout.write(template_text("envelope" if args.envelope_template else args.platform_template))
    return 0
