"""Mobility by Grübler's count, for any mechanism and for the 6-leg platform's joint types (seed 001:
m = 6 for SPS legs). Pure arithmetic.
"""

from __future__ import annotations

from stewart_drake.workspace.limits import WorkspaceError


def gruebler_mobility(n_links: int, joint_dofs, passive_dofs: int = 0, space_dof: int = 6) -> int:
    """Grübler's count m = λ (n - j - 1) + Σ f_i - I_f (seed 001, eq. 1): ``n_links`` links including
    base and top, ``joint_dofs`` the freedom of each of the j joints, ``passive_dofs`` I_f (idle
    freedoms such as a leg spinning about its own axis), ``space_dof`` λ (6 spatial, 3 planar)."""
    f = [int(x) for x in joint_dofs]
    if space_dof not in (3, 6):
        raise WorkspaceError(WorkspaceError.SPACE_DOF.format(value=space_dof))
    if n_links < 1 or any(not 1 <= x <= space_dof for x in f):
        raise WorkspaceError(WorkspaceError.JOINTS.format(space_dof=space_dof, n=n_links, f=f))
    return space_dof * (n_links - len(f) - 1) + sum(f) - int(passive_dofs)


STEWART_JOINTS = {
    # (base joint freedom, leg joint freedom, top joint freedom, idle leg spins)
    "SPS": (3, 1, 3, 6),  # the paper's count: 12 spherical + 6 prismatic, I_f = 6
    "UPS": (2, 1, 3, 0),
    "UPU": (2, 1, 2, 0),
}


def stewart_mobility(kind: str = "SPS") -> dict:
    """Grübler's count for a 6-leg platform of joint type ``kind`` ('SPS', 'UPS', 'UPU'): 14 links
    (base, top, two per leg), 18 joints. Returns n, j, joint freedoms, I_f and m."""
    if kind not in STEWART_JOINTS:
        raise WorkspaceError(WorkspaceError.LEG_TYPE.format(kind=kind, valid=", ".join(STEWART_JOINTS)))
    fb, fp, ft, idle = STEWART_JOINTS[kind]
    dofs = [fb] * 6 + [fp] * 6 + [ft] * 6
    return {"kind": kind, "n": 14, "j": 18, "sum_f": sum(dofs), "I_f": idle, "m": gruebler_mobility(14, dofs, idle)}
