"""Local polishing in the prior's unit cube: L-BFGS-B with the exact JAX gradient (``polish_with_gradient``,
``differentiable.cube_objective``) or a batched finite-difference gradient (``polish``, for objectives that
are not the posterior, e.g. the paper's eq 25).

scipy's own finite differences call the objective once per parameter, each call a separate model
evaluation of one parameter set; the model is vectorised over parameter sets, so evaluating the point
and its D neighbours as one batch of D + 1 rows costs about as much as one row on a small data set. Forward differences with scipy's step (sqrt of machine
epsilon), taken backwards at the upper bound.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

_STEP = np.sqrt(np.finfo(float).eps)


def value_and_gradient(f, u: np.ndarray) -> tuple[float, np.ndarray]:
    """f(u) and its forward-difference gradient from one call of the batched ``f`` ((R, D) -> (R,))."""
    d = u.size
    step = np.where(u + _STEP <= 1.0, _STEP, -_STEP)
    rows = np.repeat(u[None, :], d + 1, axis=0)
    rows[1:] += np.diag(step)
    values = np.asarray(f(rows), float)
    value = float(values[0])
    if not np.isfinite(value):
        return value, np.zeros(d)
    grad = (values[1:] - value) / step
    return value, np.where(np.isfinite(grad), grad, 0.0)


def _lbfgsb(value_and_gradient, start: np.ndarray, max_iterations: int, ftol: float | None = None) -> np.ndarray:
    """L-BFGS-B on [0, 1]^D from ``start`` for a function of u returning (value, gradient): the minimum's u;
    ``ftol``: scipy's relative change of the value at which it stops (None: scipy's 2.2e-9)."""
    start = np.clip(np.asarray(start, float), 0.0, 1.0)
    options = {"maxiter": max_iterations} | ({"ftol": ftol} if ftol is not None else {})
    res = minimize(lambda u: value_and_gradient(np.clip(u, 0.0, 1.0)), start, jac=True, method="L-BFGS-B",
                   bounds=[(0.0, 1.0)] * start.size, options=options)
    return np.clip(res.x, 0.0, 1.0)


def polish(f, start: np.ndarray, max_iterations: int = 15000, ftol: float | None = None) -> tuple[float, np.ndarray]:
    """The local minimum of the batched ``f`` on [0, 1]^D nearest ``start``: (value, u); ``ftol`` as ``_lbfgsb``."""
    u = _lbfgsb(lambda u: value_and_gradient(f, u), start, max_iterations, ftol)
    return float(f(u[None, :])[0]), u


def polish_with_gradient(value_and_gradient, start: np.ndarray, max_iterations: int = 15000) -> tuple[float, np.ndarray]:
    """The local minimum on [0, 1]^D nearest ``start`` of a function returning (value, exact gradient)."""
    u = _lbfgsb(value_and_gradient, start, max_iterations)
    return float(value_and_gradient(u)[0]), u
