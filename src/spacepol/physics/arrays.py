"""Which array library a computation uses: numpy for numpy arrays (reports, criticism, data on the host),
jax.numpy for JAX arrays (inside the compiled model and likelihood), so one function serves both."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np


def array_module(*arrays):
    """jax.numpy when any of ``arrays`` is a JAX array, else numpy."""
    return jnp if any(isinstance(a, jax.Array) for a in arrays) else np
