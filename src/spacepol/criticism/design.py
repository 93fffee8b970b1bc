"""Experiment design: which further measurements would break a degeneracy the data leave.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import observables as obs
from ..infer import fisher
from ..physics.geometry import Geometry



def candidate_observables() -> list[str]:
    """The observables a candidate measurement may be: those that declare a ``design_noise``."""
    return [o.name for o in obs.every() if o.design_noise is not None]


def default_noise() -> dict[str, float]:
    """The noise assumed for a candidate measurement where the data do not tell it (relative for BRDF)."""
    return {o.name: o.design_noise for o in obs.every() if o.design_noise is not None}


@dataclass
class Candidate:
    """A measurement that could be made next: an observable at one geometry (degrees) with its noise."""
    observable: str
    theta_i: float
    theta_r: float
    dphi: float
    noise: float

    def describe(self) -> str:
        """The candidate measurement in words (observable and angles)."""
        return f"{obs.get(self.observable).title} at theta_i {self.theta_i:g}, theta_r {self.theta_r:g}, dphi {self.dphi:g} deg"


def candidate_geometry(angles=tuple(range(10, 81, 10)), azimuths=(180.0, 0.0, 90.0)) -> Geometry:
    """The grid candidates are drawn from: theta_i, theta_r over ``angles``, dphi over ``azimuths``
    (180 = forward/specular plane, 0 = back towards the source, 90 = across)."""
    ti, tr, dp = np.meshgrid(np.asarray(angles, float), np.asarray(angles, float), np.asarray(azimuths, float), indexing="ij")
    return Geometry(ti.ravel(), tr.ravel(), dp.ravel())


def _scale(likelihood, channel: str, point: dict) -> np.ndarray:
    """The channel's noise per data row (N,) at one parameter point."""
    scale = np.asarray(likelihood.scale(channel, {k: np.atleast_1d(np.asarray(v, float)) for k, v in point.items()}), float)
    return np.broadcast_to(scale[0] if scale.ndim == 2 else scale, (len(likelihood.data),))


def noise_levels(likelihood, point: dict) -> dict:
    """The noise of each observable as the data have it (median file error, or the inferred level at
    ``point``), else the observable's ``design_noise``; a relative one (BRDF's) as a relative level."""
    out = default_noise()
    for o in likelihood.objects:
        levels = []
        for ch in o.channels:
            scale = _scale(likelihood, ch, point)
            if o.relative_noise and not likelihood.inferred(ch):  # absolute errors: as a relative level
                scale = scale / np.maximum(np.abs(likelihood.observed()[ch]), 1e-300)
            levels.append(float(np.median(scale)))
        out[o.name] = float(np.median(levels))
    return out


def design(posterior, point: dict, picks: int = 3, geometry: Geometry | None = None, observables=None,
           noise: dict | None = None) -> dict:
    """Rank candidate measurements by how much they shrink the worst-measured parameter combination.

    ``point``: every parameter's value (model and noise), e.g. the posterior median. Returns a dict with
    the ridge (its parameters, direction, sd relative to the prior before), the greedy picks with the
    sd along the ridge after each, the best single measurement per observable and the findings in words."""
    lik = posterior.likelihood
    model, priors = lik.model, posterior.priors
    model_names = {p.name for p in model.parameters}
    names = [n for n in priors.names if n in model_names]
    noise = {**noise_levels(lik, point), **(noise or {})}
    values = {k: v for k, v in point.items() if k in model_names}
    # the data in hand, each channel in its likelihood's residual space (BRDF in log when its noise is relative)
    channels, jac = fisher.jacobian(model, lik.geometry, lik.objects, values, names, inferred=lik.inferred)
    info = fisher.information(jac, np.concatenate([_scale(lik, ch, point) for ch in channels]))
    prior = fisher.prior_precision(priors, names)
    prior_sd = 1.0 / np.sqrt(np.diag(prior))
    precision = info + prior

    def scaled_covariance(prec):  # the Laplace covariance in units of each prior's sd
        return np.linalg.inv(prec) / np.outer(prior_sd, prior_sd)

    def ridge_sd(prec, direction):  # posterior sd along ``direction`` (in prior-sd units)
        return float(np.sqrt(direction @ scaled_covariance(prec) @ direction))

    # a parameter at a bound of its prior (a dielectric's k = 0) is left out of the ridge: the Laplace
    # approximation does not hold there, and a model even in it (R depends on k^2) has no first-order
    # information at the bound, so it would tie with the real ridge and win or lose it on rounding
    at_bound = [n for n in names if _at_bound(priors.priors[n], values[n])]
    free = [j for j, n in enumerate(names) if n not in at_bound]
    direction = np.zeros(len(names))
    direction[free] = np.linalg.eigh(scaled_covariance(precision)[np.ix_(free, free)])[1][:, -1]  # largest eigenvalue's
    involved = [n for n, c in zip(names, direction) if abs(c) >= 0.3]
    before = ridge_sd(precision, direction)

    grid = geometry if geometry is not None else candidate_geometry()
    blocks = {}  # observable -> (candidates, per-candidate information matrices)
    for name in observables or candidate_observables():
        o = obs.get(name)
        # a candidate's noise is relative where the observable's is (log BRDF), else absolute
        cand_channels, cand_jac = fisher.jacobian(model, grid, [o], values, names, inferred=lambda ch, o=o: o.relative_noise)
        n = grid.size
        per = []
        for j in range(n):
            rows = cand_jac[[k * n + j for k in range(len(cand_channels))]]
            rows = np.where(np.isfinite(rows), rows, 0.0)  # a number the model cannot differentiate there adds nothing
            per.append(fisher.information(rows, np.full(len(rows), noise[name])))
        blocks[name] = ([Candidate(name, float(grid.theta_i[j]), float(grid.theta_r[j]), float(grid.dphi[j]), noise[name])
                         for j in range(n)], per)

    best_single, single = {}, {}
    for name, (cands, per) in blocks.items():
        sds = [ridge_sd(precision + f, direction) for f in per]
        j = int(np.argmin(sds))
        best_single[name] = {"measurement": cands[j].describe(), "shrink": before / sds[j], "sd_after": sds[j]}
        single[name] = [[c.theta_i, c.theta_r, c.dphi, before / sd] for c, sd in zip(cands, sds)]

    chosen, current = [], precision.copy()
    for _ in range(picks):
        taken = {(c["observable"], c["theta_i"], c["theta_r"], c["dphi"]) for c in chosen}  # distinct geometries
        options = [(ridge_sd(current + f, direction), name, j) for name, (cands, per) in blocks.items() for j, f in enumerate(per)
                   if (name, cands[j].theta_i, cands[j].theta_r, cands[j].dphi) not in taken]
        sd, name, j = min(options)
        current = current + blocks[name][1][j]
        pick = blocks[name][0][j]
        chosen.append({"measurement": pick.describe(), "observable": name, "theta_i": pick.theta_i, "theta_r": pick.theta_r,
                       "dphi": pick.dphi, "noise": pick.noise, "sd_after": sd, "shrink": before / sd})
    findings = [_words(involved, before, chosen, best_single, noise)]
    if at_bound:
        findings.append(f"Left out of the ridge: {', '.join(f'{n} = {values[n]:g}' for n in at_bound)}, at a bound of "
                        f"the prior, where the Laplace approximation does not hold (a model even in a parameter has no "
                        f"first-order information at its bound).")
    return {"parameters": names, "point": {n: float(values[n]) for n in names}, "noise": noise,
            "ridge": {"parameters": involved, "at_prior_bound": at_bound, "direction": {n: float(c) for n, c in zip(names, direction)},
                      "sd_relative_to_prior": before},
            "picks": chosen, "best_single": best_single, "single": single, "findings": findings}


def _at_bound(prior, value, tolerance=1e-9) -> bool:
    lo, hi = prior.bounds  # finite for every prior (checked when it is made)
    return any(abs(float(value) - b) <= tolerance * (hi - lo) for b in (lo, hi))


def _words(involved, before, chosen, best_single, noise) -> str:
    what = ", ".join(involved)
    picks = "; then ".join(f"{c['measurement']} ({c['shrink']:.1f}x)" for c in chosen)
    singles = ", ".join(f"{obs.get(name).title} at best {s['shrink']:.2f}x" for name, s in best_single.items())
    levels = ", ".join(f"{obs.get(name).title} {100 * level:.0f} %" if obs.get(name).relative_noise
                       else f"{obs.get(name).title} {level:g}" for name, level in noise.items() if name in best_single)
    if before < 0.1:  # no degeneracy to break
        return (f"No degeneracy: the worst-measured combination (along {what}) already has a posterior sd of "
                f"{before:.3f} of the prior's (Laplace approximation at the point). The best further measurements "
                f"({picks}) would narrow it little; one measurement of each kind at its best geometry: {singles}.")
    return (f"The worst-measured combination is along {what}: its posterior sd is {before:.2f} of the prior's "
            f"(Laplace approximation at the point). To break it, measure {picks} (the factor is how much the sd "
            f"along it shrinks, cumulative, at noise {levels}). One measurement of each kind at its best geometry: {singles}.")
