""" "Plausible in the other unit": when poses read in one unit leave the platform's workspace (a leg outside
the stroke, the plate below the base) but the same numbers read in the other length unit (mm ↔ m) or angle
unit (deg ↔ rad) would all be inside it, the message says so. The "mm read as metres" direction already had
a hint for far positions (``sanity.FAR_POSITION``); this one covers small numbers too, both ways (``ik --pose
0 0 0.95 0 0 0`` on a metre platform read 0.95 mm and said only "154.9 mm below L_min")."""

from __future__ import annotations

import numpy as np

from stewart_drake.core.kinematics import leg_lengths
from stewart_drake.core.sanity import above_base

OTHER_LENGTH = {"mm": ("m", 1e3), "m": ("mm", 1e-3)}  # unit -> (other unit, factor on the SI value)
OTHER_ANGLE = {"deg": ("rad", 180.0 / np.pi), "rad": ("deg", np.pi / 180.0)}


def _inside(platform, q, convention: str) -> bool:
    with np.errstate(all="ignore"):
        L = leg_lengths(platform, q, convention)
    return bool(
        np.all(np.isfinite(L))
        and np.all((L >= platform.L_min) & (L <= platform.L_max))
        and np.all(above_base(platform, q, convention))
    )


def other_unit_hint(
    platform, poses_si, length_unit: str, angle_unit: str, convention: str = "utn", option: str = "", api=False
) -> str:
    """A hint ("; read in m instead, every pose would be within the stroke: give --length-unit m") when the
    ``(n, 6)`` SI poses, read in ``length_unit``/``angle_unit``, are not all inside the workspace and the
    same numbers in the other unit would be; "" otherwise. ``option`` prefixes the option names (e.g. for a
    command whose unit options are named differently, unused here); ``api`` names the API's keyword instead
    (``length_unit=m``)."""
    q = np.asarray(poses_si, dtype=float).reshape(-1, 6)
    if _inside(platform, q, convention):
        return ""
    for unit, table, cols, name in (
        (length_unit, OTHER_LENGTH, slice(0, 3), "length"),
        (angle_unit, OTHER_ANGLE, slice(3, 6), "angle"),
    ):
        if unit not in table:
            continue
        other, factor = table[unit]
        alt = q.copy()
        alt[:, cols] *= factor
        if _inside(platform, alt, convention):
            return (
                f" (the values were read in {unit}; read in {other} every pose would be inside the workspace: "
                f"give {f'{name}_unit={other}' if api else f'{option}--{name}-unit {other}'} if that is what you meant)"
            )
    return ""
