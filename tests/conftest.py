import atexit
import os
import shutil
import tempfile

os.environ.setdefault("MPLBACKEND", "Agg")
# compiled firmware modules go to a temporary cache, never the user's (~/.cache/stewart-drake)
if "STEWART_DRAKE_CACHE" not in os.environ:
    os.environ["STEWART_DRAKE_CACHE"] = tempfile.mkdtemp(prefix="stewart-drake-test-cache-")
    atexit.register(shutil.rmtree, os.environ["STEWART_DRAKE_CACHE"], True)

import pytest  # noqa: E402

from stewart_drake import workspace as ws  # noqa: E402
from stewart_drake.core.geometry import PRESETS, load_preset  # noqa: E402
from stewart_drake.mechanisms.servo import hobby_servo_hexapod  # noqa: E402


@pytest.fixture(params=PRESETS)
def preset(request):
    """Each built-in preset, as a Platform."""
    return load_preset(request.param)


# Fixtures shared by the numpy tests and the Drake / report tests of the same object.
@pytest.fixture(scope="module")
def hexapod():
    """The hobby-servo hexapod preset."""
    return hobby_servo_hexapod()


@pytest.fixture(scope="module")
def gd():
    """The gonzalez-dutra-2009 preset (the workspace paper's platform)."""
    return load_preset("gonzalez-dutra-2009")


@pytest.fixture(scope="module")
def ws10(gd):
    """The stroke workspace at zero orientation, 10 mm grid."""
    return ws.constant_orientation_workspace(gd, resolution=0.01)


@pytest.fixture(scope="module")
def rot(gd):
    """The gonzalez-dutra-2009 rotation limits, by (axis, sign)."""
    return {(r.axis, r.sign): r for r in ws.orientation_limits(gd)}
