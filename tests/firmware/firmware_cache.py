"""A fixture for the firmware tests: compiled modules go to a temporary cache, never the user's."""

import pytest

from stewart_drake.system.c_build import CACHE_ENV


@pytest.fixture(scope="module", autouse=True)
def firmware_cache(tmp_path_factory):
    mp = pytest.MonkeyPatch()
    d = tmp_path_factory.mktemp("sd-cache")
    mp.setenv(CACHE_ENV, str(d))
    yield d
    mp.undo()
