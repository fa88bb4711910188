"""The requirements file: the template loads into SI; bad files give one line naming the file, line and field."""

from __future__ import annotations

import re

import numpy as np
import pytest

from stewart_drake.cli import main
from stewart_drake.commands.init import requirements_template_text
from stewart_drake.errors import StewartError, SynthesisError
from stewart_drake.synthesis.requirements import load_requirements

TEMPLATE = requirements_template_text()


def write(tmp_path, text, name="r.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_template_loads_in_si(tmp_path):
    req = load_requirements(write(tmp_path, TEMPLATE))
    assert req.family == "radial-6-6"
    assert req.variables == ("base_radius", "top_radius", "base_half_angle", "top_half_angle", "home_height")
    np.testing.assert_allclose(req.lower[2:4], np.radians([2, 2]))  # half-angles in deg -> rad
    np.testing.assert_allclose(req.box_hi[3:], np.radians([10, 10, 15]))
    np.testing.assert_allclose(req.v_max, [0.3, 0.3, 0.3, *np.radians([20, 20, 20])])
    assert req.stroke_ratio == 1.6 and req.stroke is None and req.stiffness == 5.0e7
    assert req.joint_cone is None  # commented out in the template
    text = TEMPLATE.replace("# joint_cone: 40 ", "joint_cone: 40 ").replace(
        "# leg_diameter: 0.08 ", "leg_diameter: 0.08 "
    )
    cone = load_requirements(write(tmp_path, text, "c.yaml"))
    assert cone.joint_cone == pytest.approx(np.radians(40)) and cone.leg_diameter == pytest.approx(0.08)


def test_millimetres_scale_lengths_not_angles(tmp_path):
    text = TEMPLATE.replace("length_unit: m ", "length_unit: mm").replace(
        "base_radius: [0.4, 1.2]", "base_radius: [400, 1200]"
    )
    text = text.replace("px: [-0.1, 0.1]", "px: [-100, 100]").replace("stiffness: 5.0e7", "stiffness: 5.0e4")
    req = load_requirements(write(tmp_path, text))
    assert req.lower[0] == pytest.approx(0.4) and req.box_lo[0] == pytest.approx(-0.1)
    assert req.stiffness == pytest.approx(5.0e7)  # N/mm -> N/m
    assert req.lower[2] == pytest.approx(np.radians(2))


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        # reversed bounds: the field and its line
        ("pz: [-0.05, 0.05]", "pz: [0.05, -0.05]", r"r\.yaml:19: workspace\.pz: \[0\.05, -0\.05\] is reversed"),
        ("top_radius: [0.2, 0.8]", "top_radius: [0.8, 0.2]", r"r\.yaml:11: variables\.top_radius: .* is reversed"),
        # unknown family
        ("family: radial-6-6", "family: radial-9", r"r\.yaml:8: family: unknown family 'radial-9'"),
        # units missing
        ("length_unit: m ", "# no length unit", r"r\.yaml: length_unit is required"),
        ("angle_unit: deg ", "angle_unit: grad", r"r\.yaml:6: angle_unit: grad is not a unit"),
        # a variable of the other family
        (
            "home_height: [0.5, 1.5]",
            "home_height: [0.5, 1.5]\n  b: [0.1, 0.2]",
            r"variables\.b: not a variable of family 'radial-6-6'",
        ),
        (
            "objectives: [peak_force, stroke]",
            "objectives: [peak_force, weight]",
            r"objectives item 2: unknown objective 'weight'",
        ),
        ("  stroke_ratio: 1.6", "  stroke_ratio: 1.6\n  stroke: [1, 2]", r"give stroke_ratio or stroke, not both"),
    ],
)
def test_bad_files_name_the_field(tmp_path, old, new, message):
    assert old in TEMPLATE
    path = write(tmp_path, TEMPLATE.replace(old, new, 1))
    with pytest.raises(StewartError, match=message):
        load_requirements(path)


def test_empty_box_is_refused(tmp_path):
    start, end = TEMPLATE.index("workspace:"), TEMPLATE.index("payload:")
    path = write(tmp_path, TEMPLATE[:start] + "workspace: {}\n" + TEMPLATE[end:])
    with pytest.raises(SynthesisError, match=r"r\.yaml:\d+: workspace: \{\} is an empty box"):
        load_requirements(path)


def test_cli_bad_file_is_one_line_exit_2(tmp_path, capsys):
    path = write(tmp_path, TEMPLATE.replace("family: radial-6-6", "family: hexapod"))
    rc = main(["optimize", "--requirements", str(path), "--out", str(tmp_path / "o"), "--workers", "0"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1
    assert re.search(r"family: unknown family 'hexapod'", err)
    assert not (tmp_path / "o").exists()  # nothing written for bad input
