"""Fused, compiled kernels for the hot path of an inversion (numba).

They compute exactly what the numpy code in ``fresnel``, ``facets`` and ``builtin_effects``
computes (tests compare them), but in one pass over (parameter sets x geometries) with the
geometry terms precomputed.  Used for the Stokes path of the isotropic
specular lobe with bulk Fresnel reflection, and for DOP from Stokes vectors.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_TWO_PI = 2.0 * math.pi


def _specular_stokes(n, k, sigma, ks, cos_b, sin2_b, sin_tan_b, tan2_a, sec4_jac, cos2eta, sin2eta, factor, ggx, out):
    """Write the specular lobe's Stokes vector (unpolarized incidence) into ``out`` (4, P, N).

    n, k, sigma, ks: (P,) parameter sets; the other inputs are (N,) geometry terms except
    ``factor`` (Pf, N) with Pf in {1, P}: the product of shadowing factors.  ``sec4_jac`` is
    sec^4(alpha) / (4 cos ti cos tr).
    """
    n_sets = n.shape[0]
    n_geo = cos_b.shape[0]
    factor_stride = 1 if factor.shape[0] > 1 else 0
    for p in range(n_sets):
        nn, kk = n[p], k[p]
        var = sigma[p] * sigma[p]
        a2 = 2.0 * var
        weight = ks[p] / (_TWO_PI * var) if not ggx else ks[p] * a2 / math.pi
        n2k2 = nn * nn - kk * kk
        nk_sq = (nn * kk) * (nn * kk)
        four_n2k2 = 4.0 * nk_sq
        row = p * factor_stride
        for j in range(n_geo):
            d = n2k2 - sin2_b[j]
            sqrt_c = math.sqrt(four_n2k2 + d * d)
            big_a2 = 0.5 * (sqrt_c + d)  # A^2 and B^2 of eqs 16-17
            b2 = 0.5 * (sqrt_c - d)
            # where one is a difference of nearly equal numbers, take it from A^2 B^2 = n^2 k^2
            if big_a2 < 1e-3 * b2:
                big_a2 = nk_sq / b2
            elif b2 < 1e-3 * big_a2:
                b2 = nk_sq / big_a2
            a = math.sqrt(max(big_a2, 0.0))
            c = cos_b[j]
            am, ap = a - c, a + c
            r_s = (am * am + b2) / (ap * ap + b2)
            st = sin_tan_b[j]
            bm, bp = a - st, a + st
            r_p = r_s * (bm * bm + b2) / (bp * bp + b2)
            if ggx:
                q = a2 + tan2_a[j]
                dist = weight / (q * q)
            else:
                dist = weight * math.exp(-tan2_a[j] / a2)
            scalar = dist * sec4_jac[j] * factor[row, j]
            half_diff = 0.5 * scalar * (r_s - r_p)
            out[0, p, j] = 0.5 * scalar * (r_s + r_p)
            out[1, p, j] = half_diff * cos2eta[j]
            out[2, p, j] = -half_diff * sin2eta[j]
            out[3, p, j] = 0.0


def _stokes_dop(stokes, out):
    """DOP = |S_pol| / S0 (0 where S0 = 0), clipped at 1 against rounding; stokes (4, P, N)."""
    n_sets, n_geo = stokes.shape[1], stokes.shape[2]
    for p in range(n_sets):
        for j in range(n_geo):
            s0 = stokes[0, p, j]
            if s0 > 0.0:
                pol = math.sqrt(stokes[1, p, j] ** 2 + stokes[2, p, j] ** 2 + stokes[3, p, j] ** 2)
                out[p, j] = min(pol / s0, 1.0)
            else:
                out[p, j] = 0.0


# One serial compilation each. (A parallel twin of each kernel was dropped: numba's on-disk cache keys
# a function by name and line, not by its ``parallel`` flag, so both dispatchers loaded whichever was
# compiled first; MCMC steps of 16 walkers then forked OpenMP threads, 10x slower on a loaded 2-core
# machine. Large batches are issue 12's compiled path.)
_specular_serial = numba.njit(cache=True)(_specular_stokes)
_dop_serial = numba.njit(cache=True)(_stokes_dop)


def specular_stokes(n, k, sigma, ks, *rest):
    _specular_serial(n, k, sigma, ks, *rest)


def stokes_dop(stokes, out):
    _dop_serial(stokes, out)


def as_sets(value, n_sets):
    """A parameter as a contiguous (P,) float array."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0 or arr.size == 1:
        return np.full(n_sets, float(arr.flat[0]))
    return np.ascontiguousarray(arr.reshape(-1))
