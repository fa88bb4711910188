"""``stewart-drake stiffness``: the 6×6 Cartesian stiffness about the rotation centre at a pose, its
principal stiffnesses and directions, the compliance and the static deflection under a payload."""

from __future__ import annotations

import sys

import numpy as np

from stewart_drake.api.design import Load, load_at_pose, stiffness_at
from stewart_drake.commands._common import add_platform_arg, add_unit_args, print_json
from stewart_drake.commands._design import add_payload_args, design_platform
from stewart_drake.core.rotations import angle_scale, length_scale, pose_to_si
from stewart_drake.design.maps import MAX_POINTS, slice_maps
from stewart_drake.design.plots import plot_slice_maps
from stewart_drake.errors import OptionError
from stewart_drake.system.output_folder import OutputFolder, atomic_folder

NAMES = ("x", "y", "z", "rx", "ry", "rz")


def add_pose_args(p) -> None:
    """The arguments ``stiffness`` and ``modes`` share: platform, pose and its units, leg stiffness, payload."""
    add_platform_arg(p, default="utn-dynamic")
    p.add_argument(
        "--pose",
        nargs=6,
        type=float,
        required=True,
        metavar=("PX", "PY", "PZ", "A", "B", "G"),
        help="the pose, in the chosen units",
    )
    add_unit_args(p)
    p.add_argument(
        "--leg-stiffness",
        type=float,
        metavar="N/m",
        help="axial stiffness of every leg (default: legs.stiffness of the platform file)",
    )
    add_payload_args(p, "in --length-unit")


def register(sub) -> None:
    p = sub.add_parser("stiffness", help="6×6 Cartesian stiffness, compliance and payload deflection at a pose")
    add_pose_args(p)
    p.add_argument(
        "--json", action="store_true", help="print JSON (SI units: N/m, N/rad, N·m/rad; deflection in m and rad)"
    )
    p.add_argument(
        "--map",
        metavar="DIR",
        help="also write maps over the x-y slice through the pose (condition number, safe region, "
        "assembly mode, minimum stiffness, softest direction, lowest frequency): DIR/maps.png and DIR/maps.npz",
    )
    p.add_argument(
        "--map-half-width",
        type=float,
        default=150.0,
        help="--map: half-width of the square slice, in --length-unit (default 150)",
    )
    p.add_argument("--map-n", type=int, default=61, help="--map: nodes per side (default 61)")
    p.set_defaults(func=run)


def load(args, check_pose: bool = True) -> Load:
    """The platform with its payload at ``--pose`` (SI), checked once (``api.design.load_at_pose``)."""
    platform = design_platform(args)
    k = length_scale(args.length_unit)
    return load_at_pose(
        platform,
        pose_to_si(np.array(args.pose), args.length_unit, args.angle_unit),
        args.leg_stiffness,
        args.convention,
        args.legs == "on",
        args.payload,
        np.asarray(args.payload_com, dtype=float) * k,
        args.gravity,
        shown_com=args.payload_com,
        unit=args.length_unit,
        check_pose=check_pose,
    )


def run(args) -> int:
    ld = load(args)
    # the --map folder's policy before the work (a refusal names --map, and what this command offers)
    maps = None if args.map is None else OutputFolder(args.map, option="--map")
    r = stiffness_at(ld)
    kl, ka = length_scale(args.length_unit), angle_scale(args.angle_unit)
    d = r.deflection  # None when the loaded platform is unstable or the deflection beyond the linear range
    out = r.to_dict() | {
        "pose": args.pose,
        "length_unit": args.length_unit,
        "angle_unit": args.angle_unit,
        "deflection_edge_units": None if d is None else np.r_[d[:3] / kl, d[3:] / ka],
        "limits": r.limits,
    }
    if maps is not None:
        write_maps(args, maps, ld.platform, ld.q, ld.k)
    if args.json:
        print_json(out)
        return _report_limits(r.limits)
    k, K, pr = r.leg_stiffness, r.matrix, r.principal
    print(
        f"platform {r.platform}, pose {args.pose} ({args.length_unit}, {args.angle_unit}, {args.convention}); legs {k[0]:.6g} N/m"
        + ("" if np.all(k == k[0]) else " ...")
    )
    print("stiffness K about the rotation centre (rows: force N, moment N·m; columns: δp m, δθ rad):")
    print(f"{'':>4}" + "".join(f"{n:>13}" for n in NAMES))
    for n, row in zip(("fx", "fy", "fz", "mx", "my", "mz"), K):
        print(f"{n:>4}" + "".join(f"{v:13.5g}" for v in row))
    for label, vals, dirs, unit in (
        ("translational", pr["translational_n_per_m"], pr["translational_directions"], "N/m"),
        ("rotational", pr["rotational_nm_per_rad"], pr["rotational_directions"], "N·m/rad"),
    ):
        print(f"principal {label} stiffness ({unit}), softest first:")
        for v, e in zip(vals, dirs):
            print(f"  {v:12.5g}  along [{e[0]:+.4f} {e[1]:+.4f} {e[2]:+.4f}]")
    if d is not None:
        print(
            f"deflection under the payload ({args.payload} kg): δp = {np.array2string(d[:3] / kl, precision=5)} {args.length_unit}, "
            f"δθ = {np.array2string(d[3:] / ka, precision=5)} {args.angle_unit}"
        )
    return _report_limits(r.limits)


def _report_limits(limits: list[str]) -> int:
    """Each limit on stderr; exit 1 if there is one (the results above are still shown)."""
    for m in limits:
        print(f"stewart-drake stiffness: {m}", file=sys.stderr)
    return 1 if limits else 0


def write_maps(args, folder: OutputFolder, platform, q, k) -> None:
    """Maps over the x-y slice through pose q, written atomically into ``folder`` (``--map``)."""
    hw = args.map_half_width * length_scale(args.length_unit)
    if not (np.isfinite(hw) and hw > 0):
        raise OptionError(OptionError.POSITIVE_LENGTH.format(option="--map-half-width", value=args.map_half_width))
    if not 2 <= args.map_n <= int(np.sqrt(MAX_POINTS)):
        raise OptionError(
            OptionError.BETWEEN.format(option="--map-n", lo=2, hi=int(np.sqrt(MAX_POINTS)), value=args.map_n)
        )
    ranges = ((q[0] - hw, q[0] + hw), (q[1] - hw, q[1] + hw))
    m = slice_maps(
        platform, (0, 1), ranges, args.map_n, base=q, k=k, gravity=args.gravity, modes=True, convention=args.convention
    )
    # deferred: pyplot is imported only when maps are drawn, after selecting the Agg backend
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with atomic_folder(folder) as tmp:
        fig = plot_slice_maps(m, args.length_unit)
        fig.savefig(tmp / "maps.png", dpi=110, bbox_inches="tight")
        plt.close(fig)
        np.savez(
            tmp / "maps.npz",
            x_m=m.u,
            y_m=m.v,
            base_pose=m.base,
            within=m.within,
            condition=m.condition,
            distance=m.distance,
            same_mode=m.same_mode,
            safe=m.safe,
            k_min_n_per_m=m.k_min,
            softest=m.softest,
            f1_hz=m.f1,
        )
