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

from stewart_drake.core.geometry import PRESETS, load_preset  # noqa: E402


@pytest.fixture(params=PRESETS)
def preset(request):
    """Each built-in preset, as a Platform."""
    return load_preset(request.param)
