import os

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

# Tests never read ../shared: bundled data come from the project's own data/ folder.
os.environ.setdefault("SPACEPOL_DATA", os.path.join(os.path.dirname(__file__), "..", "data"))


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
