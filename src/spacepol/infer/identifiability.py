"""What the data determine: parameters whose posterior barely narrows the prior, and strongly
correlated pairs, explained in words."""

from __future__ import annotations

import numpy as np

from .posterior import Posterior
from .engine_result import EngineResult

WEAK_RATIO = 0.5  # posterior 90 % width above half the prior's: barely measured
STRONG_CORRELATION = 0.8


def _prior_width(prior, rng):
    draws = prior.rescale(np.linspace(0.05, 0.95, 2))
    return float(draws[1] - draws[0])


def _spread(x):
    return float(np.subtract(*np.percentile(x, [95, 5])))


def _intensity_ratio_findings(flat, names, ks, lobe):
    """DOP is a ratio of intensities: the specular weight and a diffuse albedo enter only through their
    ratio (and, in the exact specular geometry, through k_s / (sigma^2 rho_d))."""
    log = {n: np.log(np.maximum(flat[:, names.index(n)], 1e-300)) for n in (ks, lobe) + (("sigma",) if "sigma" in names else ())}
    log["ks"] = log[ks]
    shown = "k_s" if ks == "ks" else ks
    alone = min(_spread(log["ks"]), _spread(log[lobe]))
    ratio = _spread(log["ks"] - log[lobe])
    out = []
    if ratio < 0.5 * alone:
        out.append(f"From DOP alone only the ratio {shown}/{lobe} is measured (90 % range of its log {ratio:.2f}, against "
                   f"{alone:.2f} for either alone): DOP is a ratio of intensities, so scaling both lobes together changes "
                   f"nothing. Add BRDF (intensity) data to separate them.")
    elif "sigma" in log:
        folded = _spread(log["ks"] - log[lobe] - 2 * log["sigma"])
        if folded < 0.5 * min(alone, ratio, _spread(log["sigma"])):
            out.append(f"From DOP alone only {shown}/(sigma^2 {lobe}) is measured (90 % range of its log {folded:.2f}, against "
                       f"{alone:.2f} for k_s or {lobe} alone): at the specular peak the facet distribution is 1/(2 pi sigma^2), "
                       f"so roughness folds into the intensity ratio. Off-specular geometries fix sigma; BRDF data fix k_s and {lobe}.")
    if not out:
        out.append(f"k_s and {lobe} enter DOP only as a ratio of intensities; with these data neither they nor their ratio "
                   f"is pinned down well. BRDF (intensity) data would separate them.")
    return out


NEAR_BOUND_U = 0.1  # median within the outer 10 % of the prior's probability ...
BOUND_REACH_SD = 3.5  # ... and the bound within 3.5 posterior sd of it: the bound truncates the posterior


def at_bounds(posterior: Posterior, flat: np.ndarray, names: list[str]) -> list[dict]:
    """Parameters whose posterior piles against a bound of the prior.

    Judged in the prior's own unit cube (u = prior CDF, so uniform, log-uniform and normal priors
    are treated alike): the median lies in the outer 10 % of the prior mass and the bound is within
    3.5 posterior standard deviations (from the 16th-50th percentile spread) of it.  A flat,
    unconstrained posterior (median mid-prior) is not flagged; a narrow one far from the bound neither."""
    u = posterior.priors.to_unit(flat)
    physical = {p.name: p.physical for p in posterior.priors.parameters}
    out = []
    for j, name in enumerate(names):
        q16, med, q84 = np.percentile(u[:, j], [16, 50, 84])
        for side, dist, spread, bound in (("lower", med, med - q16, posterior.priors.priors[name].lower),
                                          ("upper", 1.0 - med, q84 - med, posterior.priors.priors[name].upper)):
            if dist < NEAR_BOUND_U and dist <= BOUND_REACH_SD * max(spread, 1e-12):
                x = flat[:, j]
                lo, mid, hi = np.percentile(x, [5, 50, 95])
                is_physical = bound == physical[name][0 if side == "lower" else 1]
                out.append({"parameter": name, "side": side, "bound": float(bound), "physical_limit": bool(is_physical),
                            "median": float(mid), "q05": float(lo), "q95": float(hi)})
    return out


def bound_finding(flag: dict) -> str:
    """One at-bound flag in words: a physical limit the data are consistent with (k = 0), or a prior bound that
    cuts the posterior off (the model or the prior is wrong)."""
    name, b = flag["parameter"], flag["bound"]
    where = f"(median {flag['median']:.4g}, 90 % [{flag['q05']:.4g}, {flag['q95']:.4g}])"
    if flag["physical_limit"]:
        return (f"{name} reaches its physical limit {b:g} {where}: the data are consistent with {name} = {b:g} and the "
                f"interval is cut off there; if the material cannot have {name} = {b:g}, the model is missing an effect "
                f"that {name} absorbs.")
    return (f"{name} sits at its {flag['side']} bound {b:g} {where}: the model or the prior is wrong "
            f"(the posterior is cut off by the prior, so its interval is not a measurement).")


def identifiability(posterior: Posterior, result: EngineResult) -> dict:
    """What the draws can and cannot say about each parameter: those piled at a bound, those barely narrower than
    their prior (posterior / prior 90 % width), strongly correlated pairs, and (DOP without BRDF) intensity
    weights of which only the ratio is measured; with findings in words."""
    flat = result.flat_samples()
    names = result.names
    rng = np.random.default_rng(0)
    bounds = at_bounds(posterior, flat, names)
    findings, weak = [bound_finding(f) for f in bounds], []
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
    lik = posterior.likelihood
    # effects declare the parameter that scales their lobe; DOP, q, u and m_ij measure only ratios of them
    scales = [e.intensity for e in lik.model.effects if e.intensity in names]
    if len(scales) >= 2 and all(o.scale_free for o in lik.objects):
        findings.extend(_intensity_ratio_findings(flat, names, scales[0], scales[1]))
    for a, b, r in pairs:
        findings.append(f"{a} and {b} are strongly correlated (r = {r:+.2f}): the data fix a combination of them better than either.")
    if not findings:
        findings.append("Every parameter is well constrained, away from its prior bounds, and no pair is strongly correlated.")
    return {"width_ratio": ratios, "weak": weak, "correlated_pairs": [list(p) for p in pairs], "at_bound": bounds,
            "correlation": corr.tolist(), "findings": findings}
