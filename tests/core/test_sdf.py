"""The one SDF writer (``core/sdf.py``) and the generated models (``core/sdf_models.py``): the repository's
committed ``sdf/`` is exactly what the generator writes, and the writer's pieces are correct on their own.
No Drake here (the Drake side parses the same text in test_model, test_servo and test_leg)."""

from pathlib import Path

import numpy as np
import pytest

from stewart_drake.core.geometry import PRESETS, load_preset
from stewart_drake.core.rotations import rotation_matrix
from stewart_drake.core.sdf import (
    box_inertia,
    cylinder_inertia,
    header,
    rpy,
    visual_xml,
    xml_attr,
    xml_comment,
    xml_vec,
)
from stewart_drake.core.sdf_models import sdf_file_name, sdf_text, write_sdf
from stewart_drake.mechanisms.leg3r import Leg3R
from stewart_drake.mechanisms.servo import hobby_servo_hexapod


def _committed_sdf_folder() -> Path:
    """The repository's ``sdf/`` (found upwards from this file, wherever the test tree puts it)."""
    for d in Path(__file__).resolve().parents:
        if (d / "pyproject.toml").is_file() and (d / "sdf").is_dir():
            return d / "sdf"
    raise AssertionError(f"no sdf/ folder beside a pyproject.toml above {__file__}")


def test_committed_sdf_is_what_the_generator_writes(tmp_path):
    """All five committed models (three platform presets, the servo hexapod, the 3R leg), written through
    the same ``write_sdf`` the library offers, byte for byte; and no other .sdf lies in ``sdf/``."""
    models = [load_preset(name) for name in PRESETS] + [hobby_servo_hexapod(), Leg3R()]
    committed = _committed_sdf_folder()
    names = set()
    for model in models:
        path = write_sdf(model, tmp_path)
        names.add(path.name)
        assert path.read_bytes() == (committed / path.name).read_bytes(), (
            f"sdf/{path.name} is stale: regenerate it (see sdf/README.md)"
        )
    assert len(names) == 5 and names == {p.name for p in committed.glob("*.sdf")}


def test_writer_refuses_unknown_models():
    with pytest.raises(TypeError, match="no SDF model for a str"):
        sdf_text("utn-dynamic")
    with pytest.raises(TypeError, match="no SDF model for a int"):
        sdf_file_name(3)
    with pytest.raises(ValueError, match="unknown SDF visual geometry 'mesh'"):
        visual_xml("v", (0,) * 6, ("mesh", 1.0), "1 1 1 1")


def test_escaping_keeps_the_xml_well_formed():
    import xml.etree.ElementTree as ET

    nasty = 'a--b"<c>&d---'
    ET.fromstring(f'<x a="{xml_attr(nasty)}"/>')  # parses
    assert ET.fromstring(f'<x a="{xml_attr(nasty)}"/>').get("a") == nasty
    assert "--" not in xml_comment(nasty)
    ET.fromstring(f"<x>{header(repr(nasty))}</x>")  # a comment that does not end early
    with pytest.raises(ET.ParseError):  # what the escaping prevents
        ET.fromstring(f"<x><!-- {nasty!r} --></x>")


def test_numbers_are_deterministic():
    assert xml_vec(-0.0, 1e-20, 0.1 + 0.2, 2) == "0 1e-20 0.3 2"  # 15 significant digits, no "-0"
    assert float(xml_vec(np.pi)) == pytest.approx(np.pi, rel=1e-14)


def test_rpy_is_the_sdf_convention():
    """SDF's roll-pitch-yaw means R = Rz(yaw) Ry(pitch) Rx(roll), built here from elementary rotations."""
    roll, pitch, yaw = 0.3, -0.7, 2.1
    c, s = np.cos, np.sin
    Rx = np.array([[1, 0, 0], [0, c(roll), -s(roll)], [0, s(roll), c(roll)]])
    Ry = np.array([[c(pitch), 0, s(pitch)], [0, 1, 0], [-s(pitch), 0, c(pitch)]])
    Rz = np.array([[c(yaw), -s(yaw), 0], [s(yaw), c(yaw), 0], [0, 0, 1]])
    np.testing.assert_allclose(rpy(Rz @ Ry @ Rx), (roll, pitch, yaw), atol=1e-14)
    np.testing.assert_allclose(rotation_matrix(np.array(rpy(Rz @ Ry @ Rx)), "zyx"), Rz @ Ry @ Rx, atol=1e-15)


def test_inertias_against_point_clouds():
    """Box and rod inertias against the second moments of a uniform grid of points (midpoint rule: the
    relative error is O(1/n²) ~ 1e-5 for n = 200 cells per side, so rel=1e-4)."""
    rng = np.random.default_rng(0)
    m, (a, b, h) = 0.7, (0.3, 0.1, 0.05)
    n = 200
    g = (np.arange(n) + 0.5) / n - 0.5
    X, Y, Z = np.meshgrid(g * a, g * b, g * h, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel(), Z.ravel()], -1)
    I = m / len(pts) * (np.sum(pts * pts) * np.eye(3) - pts.T @ pts)
    np.testing.assert_allclose(box_inertia(m, (a, b, h)), I, rtol=1e-4, atol=1e-12)
    r, L = 0.02, 0.4
    k = 400_000  # uniform in the disc (sqrt radius) x uniform along the axis
    rho, phi, z = r * np.sqrt(rng.uniform(0, 1, k)), rng.uniform(0, 2 * np.pi, k), rng.uniform(-L / 2, L / 2, k)
    pts = np.stack([rho * np.cos(phi), rho * np.sin(phi), z], -1)
    I = m / k * (np.sum(pts * pts) * np.eye(3) - pts.T @ pts)
    # Monte Carlo with 4e5 samples: the second moments carry ~0.3 % relative noise; 1 % is 3 sigma.
    np.testing.assert_allclose(np.diag(cylinder_inertia(m, r, L)), np.diag(I), rtol=1e-2)


def test_models_and_their_commands_need_no_pydrake(tmp_path):
    """With pydrake unimportable (``tests/cli/_no_drake.py``), the SDF writer and the modules it stands on
    import, and ``leg sdf --write``, ``servo --write-sdf`` and ``model`` (printing the SDF) write the same
    text as the library."""
    import os
    import subprocess
    import sys

    runner = Path(__file__).resolve().parents[1] / "cli" / "_no_drake.py"
    root = next(d for d in Path(__file__).resolve().parents if (d / "stewart_drake" / "__init__.py").is_file())
    env = dict(os.environ, PYTHONPATH=str(root), MPLBACKEND="Agg")
    code = (
        "import stewart_drake.core.sdf, stewart_drake.core.sdf_models, stewart_drake.core.leg_bodies, "
        "stewart_drake.mechanisms.servo_mounting, stewart_drake.mechanisms.servo_loop, stewart_drake.core.assembly_modes, "
        "stewart_drake.core.reference_platforms, stewart_drake.core.sampling, stewart_drake.core.dynamics\n"
        "from stewart_drake.cli import main\n"
        "for argv in (['leg', 'sdf', '--write', 'a'], ['servo', '--write-sdf', 'b', '--json'], ['model', '--platform', 'utn-dynamic']):\n"
        "    assert main(argv) == 0, argv\n"
    )
    r = subprocess.run(
        [sys.executable, str(runner), "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert (tmp_path / "a" / "leg-3r.sdf").read_text() == sdf_text(Leg3R())
    assert (tmp_path / "b" / "servo-hexapod.sdf").read_text() == sdf_text(hobby_servo_hexapod())
    assert r.stdout.endswith(sdf_text(load_preset("utn-dynamic")))


def test_write_sdf_keeps_the_output_policy(tmp_path):
    """The one file writer refuses a folder that is a file and never replaces a file it did not write;
    its own file it replaces (the manifest says it wrote it)."""
    from stewart_drake.errors import OutputError

    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputError, match=r"--write-sdf '.*/f': '.*/f' exists and is not a folder"):
        write_sdf(Leg3R(), str(tmp_path / "f"), option="--write-sdf")
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "leg-3r.sdf").write_text("mine")
    with pytest.raises(OutputError, match="the file exists and was not written by stewart-drake"):
        write_sdf(Leg3R(), tmp_path / "d")
    assert (tmp_path / "d" / "leg-3r.sdf").read_text() == "mine"
    first = write_sdf(Leg3R(), tmp_path / "e")
    assert write_sdf(Leg3R(l1=0.09), tmp_path / "e") == first and first.read_text() == sdf_text(Leg3R(l1=0.09))
