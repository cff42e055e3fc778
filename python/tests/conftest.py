"""Shared set-up of the Python tests: the backend they run on and the paths they need.

LUCENT_TEST_BACKEND=cuda runs the suite on the GPU (default: cpu), as the C++ suites do.
LUCENT_CLI names the `lucent` program the image tests compare against, LUCENT_SCENES_DIR
the benchmark scenes (ctest sets both).
"""
import os
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))  # reference.py beside the tests

BACKEND = os.environ.get("LUCENT_TEST_BACKEND", "cpu")
REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def backend():
    return BACKEND


@pytest.fixture
def rng():
    return np.random.default_rng(20)


@pytest.fixture
def cli():
    path = os.environ.get("LUCENT_CLI")
    if not path or not Path(path).exists():
        pytest.fail("LUCENT_CLI must name the lucent program (ctest sets it); got " + repr(path))
    return path


@pytest.fixture
def scenes_dir():
    return Path(os.environ.get("LUCENT_SCENES_DIR", REPO.parent / "shared" / "scenes"))
