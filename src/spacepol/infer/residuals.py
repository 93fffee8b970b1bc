"""Standardised residuals and their structure: the first question of model criticism.

For each observation: r = (data - posterior-median prediction) / noise (the file's error or the
inferred noise level; BRDF in log space when its noise is relative). A model that describes the
data leaves r ~ N(0, 1), independent along every sweep. Structure shows as:

* runs: too few sign changes along a sweep (theta_r at fixed theta_i), Wald-Wolfowitz z-score;
* lag-1 autocorrelation of r along the sweeps;
* trends of r against theta_i, theta_r, dphi, phase angle or DOP level (Spearman rank correlation).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

from ..infer.inference_data import median_fit

VARIABLES = ("theta_i", "theta_r", "dphi", "phase_deg", "dop_level")


@dataclass
class ResidualReport:
    """Standardised residuals per observable and their structure: runs along sweeps, lag-1 correlation, trends."""
    observables: list[str]
    residuals: dict  # observable -> (N,) standardised residuals
    variables: dict  # name -> (N,) values
    runs: dict  # observable -> {"runs", "expected", "z", "p"}
    lag1: dict  # observable -> lag-1 autocorrelation along sweeps
    trends: dict  # observable -> {variable: {"rho", "p"}}

    def findings(self, alpha: float = 0.01) -> list[str]:
        """The structure in words: sweeps whose residuals change sign too rarely, lag-1 correlation and trends
        significant at ``alpha``."""
        out = []
        for o in self.observables:
            r = self.runs[o]
            if r["p"] < alpha and r["z"] < 0:
                out.append(f"{o}: residuals change sign {r['runs']} times along the sweeps where {r['expected']:.0f} "
                           f"are expected (z = {r['z']:.1f}, p = {r['p']:.1g}): the misfit is smooth, a missing "
                           f"physical effect rather than noise.")
            elif r["p"] < alpha:  # too many sign changes: neighbours along a sweep disagree in sign
                out.append(f"{o}: residuals change sign {r['runs']} times along the sweeps where {r['expected']:.0f} "
                           f"are expected (z = {r['z']:+.1f}, p = {r['p']:.1g}): the misfit alternates between "
                           f"neighbouring rows (off the plane, rows of opposite dphi meet along a sweep), not noise.")
            for var, t in self.trends[o].items():
                if t["p"] < alpha:
                    out.append(f"{o}: residuals trend with {var} (Spearman rho = {t['rho']:+.2f}, p = {t['p']:.1g}).")
        return out or ["No structure in the residuals at the 1 % level: consistent with noise."]

    def structured(self, alpha: float = 0.01) -> bool:
        """Any runs or trend test significant after a Bonferroni correction over all the tests."""
        p = [self.runs[o]["p"] for o in self.observables] + [t["p"] for o in self.observables for t in self.trends[o].values()]
        return bool(p) and min(p) * len(p) < alpha


def sweeps(data) -> list[np.ndarray]:
    """Index arrays of the sweeps: theta_r in order at fixed (theta_i, side of the specular plane)."""
    side = np.cos(np.radians(data.dphi)) < 0
    signed = np.where(side, data.theta_r, -data.theta_r)
    groups = []
    for ti in np.unique(np.round(data.theta_i, 6)):
        idx = np.flatnonzero(np.round(data.theta_i, 6) == ti)
        groups.append(idx[np.argsort(signed[idx])])
    return groups


def runs_test(residuals, groups) -> dict:
    """Wald-Wolfowitz runs test of residual signs, pooled over sweeps (runs counted within each)."""
    runs, n_pos, n_neg, expected, variance = 0, 0, 0, 0.0, 0.0
    for idx in groups:
        signs = np.sign(residuals[idx])
        signs = signs[signs != 0]
        if len(signs) < 2:
            continue
        p, n = int(np.sum(signs > 0)), int(np.sum(signs < 0))
        runs += 1 + int(np.sum(signs[1:] != signs[:-1]))
        n_pos, n_neg = n_pos + p, n_neg + n
        m = p + n
        if p and n:
            expected += 1 + 2 * p * n / m
            variance += 2 * p * n * (2 * p * n - m) / (m**2 * (m - 1)) if m > 1 else 0.0
        else:
            expected += 1
    z = (runs - expected) / np.sqrt(variance) if variance > 0 else 0.0
    return {"runs": runs, "expected": expected, "z": float(z), "p": float(stats.norm.cdf(z))}  # one-sided: too few runs


def lag1(residuals, groups) -> float:
    """Lag-1 autocorrelation of residuals along the sweeps ``groups`` (index arrays in sweep order); NaN without a
    sweep of three or more."""
    pairs = [(residuals[idx][:-1], residuals[idx][1:]) for idx in groups if len(idx) > 2]
    if not pairs:
        return float("nan")
    a = np.concatenate([p[0] for p in pairs])
    b = np.concatenate([p[1] for p in pairs])
    if np.ptp(a) == 0 or np.ptp(b) == 0:
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def analyse(posterior, samples, median: tuple | None = None) -> ResidualReport:
    """The ResidualReport of the posterior-median fit: standardised residuals per observable, runs test and lag-1
    correlation along the theta_r sweeps, rank correlations with the angles and the DOP level; ``median``:
    ``median_fit`` of ``samples`` where already computed."""
    data = posterior.likelihood.data
    mu, scale = median or median_fit(posterior, samples)
    res = {o: posterior.likelihood.standardise(o, mu[o], scale[o]) for o in posterior.likelihood.observables}
    geo = data.geometry
    phase = np.degrees(np.arccos(np.clip(np.sum(geo.k_i * geo.k_r, axis=-1), -1, 1)))
    dop_level = mu["dop"] if "dop" in mu else (data.dop if data.dop is not None else np.zeros(len(data)))
    variables = {"theta_i": data.theta_i, "theta_r": data.theta_r, "dphi": data.dphi, "phase_deg": phase,
                 "dop_level": dop_level}
    groups = sweeps(data)
    trends = {}
    for o, r in res.items():
        trends[o] = {}
        for name, v in variables.items():
            if np.ptp(v) == 0 or np.ptp(r) == 0:  # a constant has no trend (e.g. an element measured as exactly 0)
                continue
            rho, p = stats.spearmanr(v, r)
            trends[o][name] = {"rho": float(rho), "p": float(p)}
    return ResidualReport(
        observables=list(res), residuals=res, variables=variables,
        runs={o: runs_test(r, groups) for o, r in res.items()},
        lag1={o: lag1(r, groups) for o, r in res.items()}, trends=trends,
    )
