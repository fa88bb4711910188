import os

os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402

from stewart_drake.geometry import PRESETS, load_preset  # noqa: E402


@pytest.fixture(params=PRESETS)
def preset(request):
    """Each built-in preset, as a Platform."""
    return load_preset(request.param)
