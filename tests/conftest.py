import os

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from hypothesis import settings

# CI explores the same examples every run (a failure is reproducible, never flaky); local runs
# draw new ones each time and so keep searching.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

# The process settings the command line makes (``import spacepol`` makes none): one BLAS thread, the heap kept,
# JAX in double precision with its compilation cache; JAX's default dispatch (the CLI's tests switch it as it does)
from spacepol import configure_process  # noqa: E402

configure_process()

# Bundled data come from the project's own data/ folder only.
os.environ.setdefault("SPACEPOL_DATA", os.path.join(os.path.dirname(__file__), "..", "data"))


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
