"""The measurement noise a data set shows by itself, without any model: from geometries measured twice, and for
the Mueller matrix and the BRDF from reciprocal pairs (source and detector swapped, where a passive sample gives
M(r -> i, -dphi) = Q M(i -> r, dphi)^T Q, Q = diag(1, 1, -1, 1), and the same BRDF).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..observables.mueller import RECIPROCITY_SIGNS
_MAD_TO_SIGMA = 1.482602218505602
_MAD_RELATIVE_SE = 1.166  # sqrt(1 / (2 x 0.3675)): relative standard error of a MAD-based sigma, times sqrt(K)
MIN_DIFFERENCES = 20  # fewer differences measure nothing worth a floor


@dataclass(frozen=True)
class MeasuredNoise:
    """The noise level ``value`` of the channels held by nuisance parameter ``parameter``, measured from
    ``n_differences`` differences of repeated or reciprocal measurements (``source``)."""

    parameter: str
    value: float
    n_differences: int
    source: str

    @property
    def standard_error(self) -> float:
        """The estimate's standard error (a median absolute deviation's, from ``n_differences`` differences)."""
        return _MAD_RELATIVE_SE * self.value / np.sqrt(self.n_differences)

    @property
    def floor(self) -> float:
        """The lowest noise level the data allow: the estimate less two standard errors (never below half of it)."""
        return max(self.value - 2.0 * self.standard_error, 0.5 * self.value)

    def to_json(self) -> dict:
        """The estimate, its standard error, the floor and where it came from."""
        return {"measured": self.value, "standard_error": self.standard_error, "floor": self.floor,
                "n_differences": self.n_differences, "source": self.source}


def _keys(theta_i, theta_r, dphi, wl, tol) -> list[tuple]:
    """One hashable key per row: the geometry rounded to ``tol`` degrees and the wavelength to 1e-4 um."""
    # NIST's file stores normal incidence as 0.001 deg and normal reflection as 0: both are 0 here
    theta_i = np.where(np.abs(theta_i) < 0.01, 0.0, theta_i)
    theta_r = np.where(np.abs(theta_r) < 0.01, 0.0, theta_r)
    dphi = (dphi + 180.0) % 360.0 - 180.0
    dphi = np.where(np.abs(dphi + 180.0) < tol, 180.0, dphi)
    rounded = np.column_stack([np.round(theta_i / tol), np.round(theta_r / tol), np.round(dphi / tol), np.round(wl * 1e4)])
    return list(map(tuple, rounded.astype(np.int64).tolist()))


def _wavelengths(data) -> np.ndarray:
    return np.zeros(len(data)) if data.wavelength_um is None else np.asarray(data.wavelength_um, float)


def _matched(data, theta_i, theta_r, dphi, tolerance_deg: float, keep) -> np.ndarray:
    """(K, 2) row indices (j, k): row j moved to (theta_i[j], theta_r[j], dphi[j]) is row k's measured geometry (same
    wavelength), for the pairs ``keep(j, k)`` accepts."""
    wl = _wavelengths(data)
    rows: dict = {}
    for j, key in enumerate(_keys(data.theta_i, data.theta_r, data.dphi, wl, tolerance_deg)):
        rows.setdefault(key, []).append(j)
    moved = _keys(theta_i, theta_r, dphi, wl, tolerance_deg)
    pairs = [(j, k) for j, key in enumerate(moved) for k in rows.get(key, []) if keep(j, k)]
    return np.array(pairs, int).reshape(-1, 2)


def reciprocal_pairs(data, tolerance_deg: float = 0.01) -> np.ndarray:
    """(K, 2) row indices (a, b), a < b or a = b, of measured geometries that are each other's swap
    (theta_i and theta_r exchanged, dphi of opposite sign, same wavelength). a = b where theta_i = theta_r
    and dphi is 0 or 180 deg: reciprocity then constrains the matrix itself (m12 = m21, m13 = -m31, ...)."""
    return _matched(data, data.theta_r, data.theta_i, -np.asarray(data.dphi, float), tolerance_deg, lambda j, k: j <= k)


def mirror_pairs(data, tolerance_deg: float = 0.01) -> np.ndarray:
    """(K, 2) row indices (a, b), a < b, of geometries measured at dphi and -dphi with the same theta_i, theta_r and
    wavelength (an isotropic sample's mirror images)."""
    return _matched(data, data.theta_i, data.theta_r, -np.asarray(data.dphi, float), tolerance_deg, lambda j, k: j < k)


def repeated_pairs(data, tolerance_deg: float = 0.01) -> np.ndarray:
    """(K, 2) row indices (a, b), a < b, of geometries measured more than once (each later row with the first)."""
    first: dict = {}
    pairs = []
    for j, key in enumerate(_keys(data.theta_i, data.theta_r, data.dphi, _wavelengths(data), tolerance_deg)):
        if key in first:
            pairs.append((first[key], j))
        else:
            first[key] = j
    return np.array(pairs, int).reshape(-1, 2)


def _in_level_units(likelihood, differences, first, second) -> np.ndarray:
    """Pair differences over the noise profile of their two members ((rows, channel) each): a difference of numbers
    whose noise is the level times f1 and f2 has the SD of level x sqrt(f1^2 + f2^2); divided by
    sqrt((f1^2 + f2^2) / 2) it measures the level where the profile is 1, as differences of equal noise do."""
    def profile_at(rows, channel):
        profile = likelihood.noise_profile(channel)
        return np.ones(len(rows)) if profile is None else profile[rows]

    f1, f2 = profile_at(*first), profile_at(*second)
    return np.asarray(differences, float) / np.sqrt(0.5 * (f1**2 + f2**2))


def _differences(likelihood, pairs_reciprocal, pairs_repeated) -> dict[str, dict]:
    """{noise parameter: {source: [arrays of differences]}} for every inferred channel of the likelihood, each in
    units of the level where the channel's noise profile is 1 (``_in_level_units``)."""
    out: dict[str, dict] = {}
    observed = likelihood.observed()
    for channel, y in observed.items():
        parameter = likelihood.noise_parameter(channel)
        if parameter is None:  # the file gives errors: nothing to infer
            continue
        owner = likelihood.observable_of(channel)
        sources = out.setdefault(parameter, {})
        if len(pairs_repeated):
            a, b = pairs_repeated.T
            d = owner.residual(channel, y[b], y[a], True)
            sources.setdefault("repeated geometries", []).append(_in_level_units(likelihood, d, (b, channel), (a, channel)))
        if not len(pairs_reciprocal):
            continue
        d = owner.reciprocal_differences(channel, observed, pairs_reciprocal, likelihood.inferred(channel))
        if d is None:
            continue
        members = owner.reciprocal_members(channel, pairs_reciprocal)
        if members is not None:
            d = _in_level_units(likelihood, d, *members)
        sources.setdefault("reciprocal pairs", []).append(np.asarray(d, float))
    return out


def sd_from_pair_differences(differences) -> float:
    """The robust SD of one measurement from differences of pairs that should be equal: their median absolute value
    scaled to a Gaussian's SD, over sqrt(2) (each difference holds two measurements' noise)."""
    return _MAD_TO_SIGMA * float(np.median(np.abs(differences))) / np.sqrt(2.0)


def measure(likelihood) -> dict[str, MeasuredNoise]:
    """{noise parameter: MeasuredNoise} for the likelihood's inferred noise levels that the data measure
    themselves (at least ``MIN_DIFFERENCES`` finite differences)."""
    data = likelihood.data
    reciprocal, repeated = reciprocal_pairs(data), repeated_pairs(data)
    if not len(reciprocal) and not len(repeated):
        return {}
    out = {}
    for parameter, sources in _differences(likelihood, reciprocal, repeated).items():
        parts = {name: np.concatenate([np.ravel(p) for p in arrays]) for name, arrays in sources.items()}
        parts = {name: d[np.isfinite(d)] for name, d in parts.items()}
        source = " and ".join(name for name, d in parts.items() if d.size)
        d = np.concatenate(list(parts.values())) if parts else np.empty(0)
        if d.size < MIN_DIFFERENCES:
            continue
        value = sd_from_pair_differences(d)
        if value > 0:
            out[parameter] = MeasuredNoise(parameter, value, int(d.size), source)
    return out


__all__ = ["MeasuredNoise", "RECIPROCITY_SIGNS", "measure", "mirror_pairs", "reciprocal_pairs", "repeated_pairs",
           "sd_from_pair_differences"]
