"""The seed-001 requirements and the design ``optimize`` chooses on them, shared by the performance-proof tests."""

from importlib import resources

import numpy as np
import pytest

from stewart_drake.synthesis.families import design_platform
from stewart_drake.synthesis.requirements import load_requirements

SEED_001 = resources.files("stewart_drake") / "examples" / "seed_001_requirements.yaml"
# the design optimize chooses on seed 001 (seed 0): base and plate radii, half-angles, home height
X = np.array([0.4237, 0.1567, np.radians(5.737), np.radians(3.179), 0.8729])


@pytest.fixture(scope="module")
def req():
    return load_requirements(SEED_001)


@pytest.fixture(scope="module")
def design(req):
    return design_platform(req, X, [0.80, 1.09])
