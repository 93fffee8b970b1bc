"""The likelihood of a light curve's measured points, and replicates of them: the flux Gaussian with the file's error;
DoLP and AoP as a camera measures them, from normalized Stokes parameters q, u with Gaussian errors (exact where the
polarization is near its noise, where a Gaussian about the DoLP is biased).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np
from scipy.special import erfc, erfcx, i0e

from ..observables.aop import wrap_deg

_LOG_SQRT_2PI = 0.5 * np.log(2.0 * np.pi)
_TINY = 1e-300


def _gaussian(residual, error):
    return -0.5 * (residual / error) ** 2 - np.log(error) - _LOG_SQRT_2PI


def rice_log_pdf(measured, true, sigma):
    """ln of the Rice density of a measured DoLP ``measured`` given the true ``true`` and the per-component noise
    ``sigma`` of q and u (broadcast together); a DoLP measured negative (its flux below zero) by its size."""
    x = np.maximum(np.abs(measured), _TINY)
    z = x * true / sigma**2
    return np.log(x / sigma**2) - 0.5 * ((x - true) / sigma) ** 2 + np.log(i0e(z))


def angle_log_pdf(difference_deg, true_dolp, sigma):
    """ln of the density (per degree) of a measured AoP ``difference_deg`` from the true AoP, given the true DoLP and
    the per-component noise ``sigma`` of q and u; uniform over 180 deg where the true DoLP is 0."""
    eta = true_dolp / sigma
    xi = eta * np.cos(np.radians(2.0 * difference_deg)) / np.sqrt(2.0)
    # ln(1 + sqrt(pi) xi exp(xi^2) (1 + erf(xi))): above zero in logs (exp(xi^2) overflows where the polarization is
    # far above its noise); below, with exp(xi^2) erfc(-xi) as erfcx(-xi), and far below by its asymptotic series (the
    # direct sum cancels to nothing there)
    up = np.maximum(xi, 1e-300)
    above = np.logaddexp(0.0, np.log(np.sqrt(np.pi) * up) + up**2 + np.log(erfc(-up)))
    down = np.minimum(xi, 0.0)
    x = np.maximum(-down, 30.0)
    tail = 1.0 / (2 * x**2) - 3.0 / (4 * x**4) + 15.0 / (8 * x**6)
    below = np.log(np.maximum(np.where(down > -30.0, 1.0 + np.sqrt(np.pi) * down * erfcx(-down), tail), _TINY))
    return -np.log(np.pi) - 0.5 * eta**2 + np.where(xi > 0.0, above, below) + np.log(np.pi / 180.0)


def pointwise(curve, observables: list[str], mu: dict) -> np.ndarray:
    """(S, M) the log-likelihood of each measured number (``observables`` in order, then times) given the model's
    values ``mu`` ({flux, dolp, aop_deg}: (S, T); NaN where no light, read as 0 flux and DoLP)."""
    flux, p0 = np.nan_to_num(mu["flux"]), np.nan_to_num(mu["dolp"])
    theta0 = np.nan_to_num(mu["aop_deg"])
    terms = {}
    if "flux" in observables:
        terms["flux"] = _gaussian(curve.flux - flux, curve.flux_err)
    both = "dolp" in observables and "aop_deg" in observables
    if both:
        difference = np.radians(2.0 * (curve.aop_deg - theta0))
        terms["dolp"] = _gaussian(curve.dolp - p0 * np.cos(difference), curve.dolp_err)
        terms["aop_deg"] = (-0.5 * (p0 * np.sin(difference) / _across(curve)) ** 2 - np.log(curve.aop_err_deg)
                            - _LOG_SQRT_2PI)
    elif "dolp" in observables:
        terms["dolp"] = rice_log_pdf(curve.dolp, p0, curve.dolp_err)
    elif "aop_deg" in observables:
        difference = wrap_deg(curve.aop_deg - theta0)
        if curve.dolp is None:
            terms["aop_deg"] = _gaussian(difference, curve.aop_err_deg)
        else:
            terms["aop_deg"] = angle_log_pdf(difference, p0, curve.dolp_err)
    return np.concatenate([np.broadcast_to(terms[name], p0.shape) for name in observables], axis=1)


def _across(curve) -> np.ndarray:
    """(T,) the AoP's error in units of q and u: 2 DoLP x the AoP's error (rad); a DoLP measured negative (its flux
    below zero, in the noise) lies across the origin, so by its size."""
    return 2.0 * np.maximum(np.abs(curve.dolp), _TINY) * np.radians(curve.aop_err_deg)


def replicates(curve, mu: dict, rng: np.random.Generator) -> dict:
    """{observable: (S, T)} the model's values ``mu`` with the file's noise drawn, for each observable the curve holds:
    the flux Gaussian, DoLP and AoP from q and u with Gaussian noise (a replicated DoLP carries the measured one's
    bias)."""
    out = {}
    if curve.flux is not None:
        out["flux"] = np.nan_to_num(mu["flux"]) + curve.flux_err * rng.standard_normal(mu["flux"].shape)
    if curve.dolp is not None or curve.aop_deg is not None:
        p0, theta0 = np.nan_to_num(mu["dolp"]), np.radians(2.0 * np.nan_to_num(mu["aop_deg"]))
        sigma = curve.dolp_err if curve.dolp is not None else 2.0 * p0 * np.radians(curve.aop_err_deg)
        q = p0 * np.cos(theta0) + sigma * rng.standard_normal(p0.shape)
        u = p0 * np.sin(theta0) + sigma * rng.standard_normal(p0.shape)
        if curve.dolp is not None:
            out["dolp"] = np.hypot(q, u)
        if curve.aop_deg is not None:
            out["aop_deg"] = 0.5 * np.degrees(np.arctan2(u, q))
    return out
