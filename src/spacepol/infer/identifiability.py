"""What the data determine: parameters whose posterior barely narrows the prior, and strongly
correlated pairs, explained in words."""

from __future__ import annotations

import numpy as np

from .posterior import Posterior
from .result import Result

WEAK_RATIO = 0.5  # posterior 90 % width above half the prior's: barely measured
STRONG_CORRELATION = 0.8


def _prior_width(prior, rng):
    draws = prior.rescale(np.linspace(0.05, 0.95, 2))
    return float(draws[1] - draws[0])


def identifiability(posterior: Posterior, result: Result) -> dict:
    flat = result.flat_samples()
    names = result.names
    rng = np.random.default_rng(0)
    findings, weak = [], []
    ratios = {}
    for j, name in enumerate(names):
        post_width = float(np.subtract(*np.percentile(flat[:, j], [95, 5])))
        prior_width = _prior_width(posterior.priors.priors[name], rng)
        ratios[name] = post_width / prior_width if prior_width > 0 else np.nan
        if ratios[name] > WEAK_RATIO:
            weak.append(name)
            findings.append(f"{name}: the data barely constrain it (90 % interval spans {100 * ratios[name]:.0f} % of the prior's).")
    corr = np.corrcoef(flat.T) if flat.shape[0] > 2 else np.eye(len(names))
    pairs = []
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            if abs(corr[a, b]) > STRONG_CORRELATION:
                pairs.append((names[a], names[b], float(corr[a, b])))
    observables = posterior.likelihood.observables
    lobes = [n for n in ("rho_d", "rho_pd") if n in names]
    if "ks" in names and lobes and "brdf" not in observables:
        lobe = lobes[0]
        j_ks, j_l = names.index("ks"), names.index(lobe)
        ratio = np.log(np.maximum(flat[:, j_ks], 1e-300) / np.maximum(flat[:, j_l], 1e-300))
        spread_ratio = float(np.subtract(*np.percentile(ratio, [95, 5])))
        spread_each = float(np.subtract(*np.percentile(np.log(np.maximum(flat[:, j_ks], 1e-300)), [95, 5])))
        findings.append(
            f"From DOP alone only the ratio k_s/{lobe} is measured (its log has a 90 % range of "
            f"{spread_ratio:.2f}, against {spread_each:.2f} for log k_s alone): DOP is a ratio of intensities, "
            f"so scaling both lobes together changes nothing. Add BRDF (intensity) data to separate them."
        )
    for a, b, r in pairs:
        findings.append(f"{a} and {b} are strongly correlated (r = {r:+.2f}): the data fix a combination of them better than either.")
    if not findings:
        findings.append("Every parameter is well constrained and no pair is strongly correlated.")
    return {"width_ratio": ratios, "weak": weak, "correlated_pairs": [list(p) for p in pairs],
            "correlation": corr.tolist(), "findings": findings}
