"""``stewart-drake response``: the closed leg loop in the frequency domain about a held pose (margins, bandwidth,
sensitivity peak; Bode and Nyquist plots), optionally measured on the nonlinear Drake loop."""

from __future__ import annotations

import math
import sys

import numpy as np

from stewart_drake.api.response import loop_response
from stewart_drake.commands._common import add_force_arg, add_platform_arg, dumps_strict, output_folder, print_json
from stewart_drake.errors import UsageError
from stewart_drake.spec import apply_overrides, load_machine
from stewart_drake.system.output_folder import atomic_folder

HELP = "the closed leg loop in the frequency domain at a pose: margins, bandwidth, sensitivity peak, Bode/Nyquist"
# the files response writes into --out
FILES = ("response.json", "response.png")


def register(sub) -> None:
    p = sub.add_parser("response", help=HELP)
    add_platform_arg(p, default=None)
    p.add_argument("--machine", default=None, metavar="FILE", help="a machine file (default: --platform, utn-dynamic)")
    p.add_argument(
        "--set", action="append", default=[], metavar="PATH=VALUE", help="set one field of the machine by its spec path"
    )
    p.add_argument("--controller", choices=["fixed", "float"], default=None, help="the law (default: the machine's)")
    p.add_argument(
        "--pose",
        nargs=6,
        type=float,
        default=None,
        metavar=("PX", "PY", "PZ", "A", "B", "G"),
        help="the held pose, mm and degrees (default: home)",
    )
    p.add_argument(
        "--measure",
        type=float,
        action="append",
        default=None,
        metavar="HZ",
        help="also measure the response at this frequency on the nonlinear Drake loop (repeatable)",
    )
    p.add_argument("--out", default=None, metavar="DIR", help="write response.json and response.png (Bode, Nyquist)")
    add_force_arg(p)
    p.set_defaults(func=run)


def run(args) -> int:
    if args.machine is not None and args.platform is not None:
        raise UsageError(UsageError.NOT_BOTH.format(first="--machine", second="--platform"))
    out_folder = output_folder(args, names=FILES)
    machine = load_machine(args.machine or args.platform or "utn-dynamic")
    if args.controller is not None:
        machine = apply_overrides(machine, {"controller.law": args.controller})
    machine = apply_overrides(machine, args.set)
    pose = None
    if args.pose is not None:
        pose = np.array(args.pose[:3] + [math.radians(a) for a in args.pose[3:]])
        pose[:3] /= 1e3
    r = loop_response(machine, pose, measure=args.measure)
    d = r.to_dict()
    summary = {k: v for k, v in d.items() if k not in ("frequencies_hz", "setpoint", "cartesian", "loop")}
    if out_folder is not None:
        # deferred: pyplot is loaded only when a figure is written
        import matplotlib

        matplotlib.use("Agg")
        with atomic_folder(out_folder) as tmp:
            (tmp / "response.json").write_text(dumps_strict(d))
            r.plot().savefig(tmp / "response.png", dpi=100)
    print_json(summary)
    for f in r.failures:
        print(f"stewart-drake response: {f}", file=sys.stderr)
    return 0 if r.ok else 1
