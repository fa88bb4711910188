"""The platform drawing says which joint is which: leg i's line joins base joint i to the plate joint that carries
it (read back from the figure's own line data), shared joints carry one label naming each leg, and
``model --figure`` writes that figure as a new PNG without touching other files."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from stewart_drake.core.geometry import load_preset
from stewart_drake.core.kinematics import plate_anchors
from stewart_drake.design.drawings import convention_figure, platform_figure

matplotlib.use("Agg")


@pytest.mark.parametrize("name", ["utn-kinematic", "gonzalez-dutra-2009"])
def test_leg_lines_join_the_joints_of_their_leg(name):
    p = load_preset(name)
    pose = p.home_pose() + np.array([0.01, -0.02, 0.0, 0.05, -0.03, 0.1])
    fig = platform_figure(p, pose)
    top_view, side_view = fig.axes[:2]
    base, top = p.base_anchors * 1e3, plate_anchors(p, pose) * 1e3
    for i in range(6):
        (line,) = [ln for ln in top_view.lines if ln.get_label() == f"leg {i + 1}"]
        # exact: the line holds the very numbers it was given, in mm
        np.testing.assert_allclose(line.get_xydata(), [base[i, :2], top[i, :2]], rtol=0, atol=1e-9)
        (side,) = [ln for ln in side_view.lines if ln.get_label() == f"leg {i + 1}"]
        np.testing.assert_allclose(side.get_xydata(), [base[i, [0, 2]], top[i, [0, 2]]], rtol=0, atol=1e-9)


def test_shared_joints_name_each_of_their_legs():
    """utn-kinematic is a 3-6 platform: its three plate joints carry legs (1, 2), (3, 4), (5, 6)."""
    p = load_preset("utn-kinematic")
    texts = {t.get_text() for t in platform_figure(p).axes[0].texts}
    plate = sorted(t for t in texts if t.startswith("T"))
    expected = sorted("T" + ",".join(str(i + 1) for i in np.flatnonzero(p.leg_top == j)) for j in range(3))
    assert plate == expected
    assert sorted(t for t in texts if t.startswith("B")) == [f"B{i}" for i in range(1, 7)]


def test_convention_figure_turns_the_plate_by_the_right_hand_rule():
    """Seen from the tip of the axis it turns about, a positive angle moves the plate counter-clockwise: the
    cross product of a plate point's position before and after the turn (in the view's axes) is positive."""
    p = load_preset("gonzalez-dutra-2009")
    for ax in convention_figure(p).axes:
        home, turned = (ln.get_xydata() for ln in ax.lines if ln.get_label() in ("home",) or "= +" in ln.get_label())
        centre = home[:-1].mean(axis=0)
        a, b = home[0] - centre, turned[0] - centre
        assert a[0] * b[1] - a[1] * b[0] > 0, ax.get_title()


def test_model_figure_writes_a_new_png(tmp_path, capsys):
    from stewart_drake.cli import main

    target = tmp_path / "my.png"
    assert main(["model", "--platform", "utn-dynamic", "--figure", str(target)]) == 0
    assert target.read_bytes().startswith(b"\x89PNG")
    other = tmp_path / "theirs.png"
    other.write_bytes(b"not ours")
    assert main(["model", "--platform", "utn-dynamic", "--figure", str(other)]) == 2
    assert other.read_bytes() == b"not ours"
    assert "--figure" in capsys.readouterr().err


def test_plot_platform_checks_its_pose():
    import stewart_drake as sd

    p = sd.load_platform("utn-dynamic")
    assert len(sd.plot_platform(p).axes) == 2
    for bad in ([0, 0, 0.7], [0, 0, np.nan, 0, 0, 0], [0, 0, 700, 0, 0, 0], [0j, 0, 0.7, 0, 0, 0], "home"):
        with pytest.raises(sd.StewartError):
            sd.plot_platform(p, bad)
