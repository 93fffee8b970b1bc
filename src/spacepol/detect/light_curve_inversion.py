"""A satellite's material and attitude from its light curve: for each candidate material the joint posterior of the
material's parameters and the attitude offsets (emcee), ranked by ELPD-LOO (PSIS over the light curve's points).

The likelihood: each measured point (flux, DoLP, AoP at a time) is Gaussian about the model's value with the
file's 1-sigma error; an AoP residual is taken on its 180-deg circle. The posterior is narrow and its optima many (a
box's faces alike under a turn; a narrow glint of smooth facets against a broad one of rough facets): the walkers
start about the global optimum of a differential-evolution search (``_start``) and explore that optimum's mode only.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass

import arviz as az
import emcee
import numpy as np

from ..errors import ParameterError
from ..infer.diagnostics import loo
from ..io.light_curve import OBSERVABLES
from ..orbit.attitude import ANGLES
from .light_curve_model import LightCurveModel
from .target import linear_polarization

GENERATIONS = 300  # at most, of the differential-evolution search that places the walkers
DRAWS_FOR_LOO = 2000
BLOCK = 16  # sets per model evaluation (its cost grows as the square of the sets)


def predicted(model: LightCurveModel, theta: np.ndarray) -> dict[str, np.ndarray]:
    """{flux, dolp, aop_deg: (S, T)} the model's values for rows ``theta`` (NaN DoLP and AoP where no light)."""
    s0, s1, s2 = np.concatenate([model.stokes(theta[i : i + BLOCK]) for i in range(0, len(theta), BLOCK)], axis=1)
    dolp, aop = linear_polarization(s0, s1, s2)
    return {"flux": s0, "dolp": dolp, "aop_deg": aop}


def _wrapped_aop(difference):
    """An AoP difference (deg) on its 180-deg circle, in [-90, 90)."""
    return (difference + 90.0) % 180.0 - 90.0


def pointwise_log_likelihood(model: LightCurveModel, curve, observables: list[str], theta: np.ndarray) -> np.ndarray:
    """(S, M) the log-likelihood of each measured number (observables in order, then times) at rows ``theta``."""
    mu = predicted(model, theta)
    parts = []
    for name in observables:
        measured, error = getattr(curve, name), getattr(curve, OBSERVABLES[name])
        residual = measured - np.nan_to_num(mu[name])  # no light predicted: a model of 0 flux, DoLP and AoP
        if name == "aop_deg":
            residual = _wrapped_aop(residual)
        parts.append(-0.5 * (residual / error) ** 2 - np.log(error * np.sqrt(2 * np.pi)))
    return np.concatenate(parts, axis=1)


@dataclass
class MaterialFit:
    """One candidate's posterior: ``names``, ``samples`` (draws, D), the ELPD-LOO record (``loo``: elpd_loo,
    elpd_loo_se, p_loo, pareto_k, pointwise), emcee's ``rhat_max``, ``ess_min`` and ``acceptance``, the
    posterior-predictive bands {observable: (3, T) 5/50/95 %}, and ``seconds``."""

    material: str
    description: str
    names: list[str]
    samples: np.ndarray
    loo: dict
    rhat_max: float
    ess_min: float
    acceptance: float
    bands: dict
    seconds: float

    def save(self, path, key: str) -> None:
        """This fit in one .npz file (written whole or not at all), labelled with ``key`` (what it was fitted to)."""
        from ..io.atomic import atomic_path

        scalars = {"material": self.material, "description": self.description, "names": self.names, "key": key,
                   "rhat_max": self.rhat_max, "ess_min": self.ess_min, "acceptance": self.acceptance,
                   "seconds": self.seconds, "loo": {k: v for k, v in self.loo.items() if np.ndim(v) == 0 or k == "pareto_k_bad"}}
        arrays = {"samples": self.samples, "pointwise": self.loo["pointwise"], "pareto_k": self.loo["pareto_k"]}
        arrays |= {f"band_{k}": v for k, v in self.bands.items()}
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as handle:
                np.savez(handle, scalars=np.array(json.dumps(scalars)), **arrays)

    @classmethod
    def load(cls, path, key: str) -> "MaterialFit | None":
        """The fit saved at ``path`` for ``key``; None where there is none, it was fitted to something else, or the
        file cannot be read (a run killed while writing it)."""
        try:
            with np.load(path) as f:
                scalars = json.loads(str(f["scalars"]))
                if scalars["key"] != key:
                    return None
                bands = {k.removeprefix("band_"): f[k] for k in f.files if k.startswith("band_")}
                record = scalars["loo"] | {"pointwise": f["pointwise"], "pareto_k": f["pareto_k"]}
                return cls(scalars["material"], scalars["description"], scalars["names"], f["samples"], record,
                           scalars["rhat_max"], scalars["ess_min"], scalars["acceptance"], bands, scalars["seconds"])
        except (OSError, ValueError, KeyError, EOFError):
            return None

    def summary(self) -> dict:
        """{parameter: {median, q05, q95}} over the posterior draws."""
        q = np.percentile(self.samples, [50, 5, 95], axis=0)
        return {n: {"median": float(q[0, j]), "q05": float(q[1, j]), "q95": float(q[2, j])} for j, n in enumerate(self.names)}


def fit_material(model: LightCurveModel, curve, observables: list[str], rng: np.random.Generator, steps: int = 3000,
                 walkers: int | None = None, progress: bool = False) -> MaterialFit:
    """``model``'s posterior given ``curve``'s ``observables`` (emcee, the second half of ``steps`` kept)."""
    start = time.perf_counter()
    walkers = walkers or max(32, 4 * model.ndim)
    walkers += walkers % 2

    def log_prob(theta):
        theta = np.atleast_2d(theta)
        prior = model.log_prior(theta)
        out = np.full(len(theta), -np.inf)
        ok = np.isfinite(prior)
        if ok.any():
            out[ok] = prior[ok] + pointwise_log_likelihood(model, curve, observables, theta[ok]).sum(axis=1)
        return out

    initial = _start(model, log_prob, rng, walkers)
    sampler = emcee.EnsembleSampler(walkers, model.ndim, log_prob, vectorize=True,
                                    moves=[(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)])
    sampler.random_state = np.random.RandomState(int(rng.integers(2**32))).get_state()
    for k, _ in enumerate(sampler.sample(initial, iterations=steps)):
        if progress and (k + 1) % max(1, steps // 5) == 0:
            print(f"  {model.material.name}: {k + 1}/{steps} steps, {time.perf_counter() - start:.0f} s", file=sys.stderr)
    chain = sampler.get_chain(discard=steps // 2)  # (draws, walkers, D)
    posterior = {n: chain[:, :, j].T for j, n in enumerate(model.names)}  # (chain, draw) for ArviZ
    rhat = az.rhat(az.from_dict(posterior=posterior))
    ess = az.ess(az.from_dict(posterior=posterior))
    flat = chain.reshape(-1, model.ndim)
    kept = flat[rng.choice(len(flat), min(DRAWS_FOR_LOO, len(flat)), replace=False)]
    ll = np.concatenate([pointwise_log_likelihood(model, curve, observables, kept[i : i + BLOCK])
                         for i in range(0, len(kept), BLOCK)])
    labels = [f"{name}[{t:%H:%M:%S}]" for name in observables for t in curve.times_utc]
    record = loo(az.from_dict(posterior={n: kept[None, :, j] for j, n in enumerate(model.names)},
                              log_likelihood={"y": ll[None]}, coords={"obs_id": labels}, dims={"y": ["obs_id"]}))
    return MaterialFit(model.material.name, model.material.description, list(model.names), kept, record,
                       float(max(rhat[n].item() for n in model.names)), float(min(ess[n].item() for n in model.names)),
                       float(np.mean(sampler.acceptance_fraction)), _bands(model, curve, kept[:200], rng),
                       time.perf_counter() - start)


def _start(model: LightCurveModel, log_prob, rng: np.random.Generator, walkers: int) -> np.ndarray:
    """(walkers, D) starting points: the global optimum of a differential-evolution search of the prior's unit cube
    (scipy, its generations evaluated in blocks), polished by L-BFGS-B (forward differences, one batch of D + 1 sets
    per gradient); the walkers spread about it by each coordinate's own curvature there."""
    from scipy.optimize import differential_evolution, minimize

    d = model.ndim

    def to_theta(u):
        u = np.clip(np.atleast_2d(u), 1e-12, 1 - 1e-12)
        return np.column_stack([p.rescale(u[:, j]) for j, p in enumerate(model.priors)])

    def negative(columns):  # (D, S) -> (S,), as scipy's vectorized search calls it
        theta = to_theta(np.asarray(columns).T)
        values = np.concatenate([log_prob(theta[i : i + BLOCK]) for i in range(0, len(theta), BLOCK)])
        return np.where(np.isfinite(values), -values, 1e300)

    found = differential_evolution(negative, [(0.0, 1.0)] * d, vectorized=True, updating="deferred", popsize=15,
                                   maxiter=GENERATIONS, tol=1e-8, polish=False, seed=int(rng.integers(2**32)))

    def objective(u):
        # forward differences away from the cube's nearer face: D + 1 sets per call (a model call costs their square)
        h = np.where(u < 0.5, 1e-7, -1e-7)
        rows = np.repeat(u[None, :], d + 1, axis=0)
        rows[1:] += np.diag(h)
        v = log_prob(to_theta(rows))
        if not np.isfinite(v[0]):
            return 1e300, np.zeros(d)
        grad = np.where(np.isfinite(v[1:]), (v[1:] - v[0]) / h, 0.0)
        return -float(v[0]), -grad

    polished = minimize(objective, np.clip(found.x, 1e-9, 1 - 1e-9), jac=True, method="L-BFGS-B",
                        bounds=[(1e-9, 1 - 1e-9)] * d, options={"maxiter": 500})
    best_u = polished.x if polished.fun <= found.fun else found.x
    # each coordinate's step to a drop of 1/2 in log posterior (its conditional SD), from a second difference
    h = 1e-4
    rows = np.repeat(best_u[None, :], 2 * d + 1, axis=0)
    rows[1 : d + 1] += np.diag(np.full(d, h))
    rows[d + 1 :] -= np.diag(np.full(d, h))
    v = log_prob(to_theta(np.clip(rows, 1e-12, 1 - 1e-12)))
    curvature = -(v[1 : d + 1] + v[d + 1 :] - 2 * v[0]) / h**2
    usable = np.isfinite(curvature) & (curvature > 0)
    spread = np.full(d, 1e-3)
    spread[usable] = 1.0 / np.sqrt(curvature[usable])
    u = best_u + 0.5 * np.minimum(spread, 0.05) * rng.standard_normal((walkers, d))
    return to_theta(np.clip(u, 1e-9, 1 - 1e-9))


def _bands(model: LightCurveModel, curve, draws: np.ndarray, rng: np.random.Generator) -> dict:
    """{observable: (3, T)} the 5/50/95 % of the posterior predictive (the model plus the file's noise)."""
    out = {}
    for name, values in predicted(model, draws).items():
        error = getattr(curve, OBSERVABLES[name])
        noise = 0.0 if error is None else error * rng.standard_normal(values.shape)
        replicated = np.nan_to_num(values) + noise
        if name == "aop_deg":
            replicated = _wrapped_aop(replicated)
        out[name] = np.percentile(replicated, [5, 50, 95], axis=0)
    return out


def ranking(fits: list[MaterialFit]) -> list[dict]:
    """The candidates by ELPD-LOO, best first, each with its difference to the best and that difference's paired SE."""
    order = sorted(fits, key=lambda f: -f.loo["elpd_loo"])
    top = order[0].loo["pointwise"]
    rows = []
    for f in order:
        d = f.loo["pointwise"] - top
        rows.append({"material": f.material, "elpd": f.loo["elpd_loo"], "elpd_se": f.loo["elpd_loo_se"],
                     "delta_elpd": float(d.sum()), "delta_elpd_se": float(np.sqrt(len(d) * np.var(d)))})
    return rows


ALIASES = {"flux": "flux", "dolp": "dolp", "aop": "aop_deg", "aop_deg": "aop_deg"}


def check_observables(curve, observables) -> list[str]:
    """The observables to fit: ``observables`` (flux, dolp, aop; None for all the curve holds), each one the curve
    holds; an unknown or missing one is one line."""
    given = curve.observables if observables is None else [o.strip() for o in observables]
    unknown = [n for n in given if n not in ALIASES]
    if unknown:
        raise ParameterError(f"--observables: no observable {', '.join(unknown)} (known: flux, dolp, aop)")
    names = list(dict.fromkeys(ALIASES[n] for n in given))
    missing = [n for n in names if n not in curve.observables]
    if missing or not names:
        raise ParameterError(f"--observables {','.join(names) or '(none)'}: {curve.source} holds "
                             f"{', '.join(curve.observables)}")
    return names


@dataclass
class LightCurveInversion:
    """Every candidate material's fit to one light curve: ``fits`` (best first by ELPD-LOO), ``ranking``
    (lightcurve.json's), the light curve itself (``curve``), the observables fitted, and the target's setting in
    words (``assumptions``)."""

    curve: object
    fits: list[MaterialFit]
    observables: list[str]
    assumptions: list[str]

    @property
    def ranking(self) -> list[dict]:
        """{material, elpd, elpd_se, delta_elpd, delta_elpd_se} best first."""
        return ranking(self.fits)

    @property
    def best(self) -> MaterialFit:
        """The fit of the material ranked first."""
        return next(f for f in self.fits if f.material == self.ranking[0]["material"])

    def to_json(self) -> dict:
        """lightcurve.json's content (DESIGN.md), with each candidate's parameters and diagnostics added."""

        best = self.best.summary()
        return {"ranking": self.ranking, "best": self.best.material,
                "attitude": {a: best[a] for a in ANGLES if a in best},
                "parameters": {k: v for k, v in best.items() if k not in ANGLES},
                "observables": self.observables,
                "candidates": {f.material: {"description": f.description, "parameters": f.summary(),
                                            "rhat_max": f.rhat_max, "ess_min": f.ess_min, "acceptance": f.acceptance,
                                            "p_loo": f.loo["p_loo"], "pareto_k_max": float(np.max(f.loo["pareto_k"])),
                                            "seconds": f.seconds} for f in self.fits},
                "times_utc": [t.strftime("%Y-%m-%dT%H:%M:%SZ") for t in self.curve.times_utc],
                "assumptions": self.assumptions}
