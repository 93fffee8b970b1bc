"""A satellite's material and attitude from its light curve: for each candidate material the joint posterior of the
material's parameters and the attitude offsets and its evidence (nested sampling, nautilus), ranked by ELPD-LOO
(PSIS over the light curve's points).

The likelihood: the flux Gaussian about the model's value with the file's 1-sigma error; DoLP and AoP as measured
from normalized Stokes q, u with Gaussian errors (``light_curve_likelihood``: unbiased where the polarization is near
its noise). The posterior is narrow and its optima many (a
box's faces alike under a turn; a narrow glint of smooth facets against a broad one of rough facets): nested
sampling shrinks from the whole prior, so it finds the modes a local sampler started at one optimum would miss.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass

import arviz as az
import numpy as np

from ..errors import ParameterError, SamplerStalled
from ..infer.diagnostics import loo
from ..orbit.attitude import ANGLES
from .attitude_modes import attitude_words
from .light_curve_likelihood import pointwise, replicates
from .light_curve_model import LightCurveModel
from .target import linear_polarization

EFFECTIVE_DRAWS = 2000  # nested sampling stops once its weighted points are worth this many independent draws
# ... or once it has spent ``nested.SAMPLING_CALLS_PER_LIVE_POINT`` likelihood calls per live point after its
# exploration: a candidate that misses the curve by millions in log L has a posterior far narrower than its last
# shell, and its weighted points gain almost no effective draws per call (white paint on a solar-glass render: 1
# effective draw after 8,000 calls)
DRAWS_FOR_LOO = 2000
# an exploration that stalls (``infer.engines.stall_guard``) starts again from the prior with twice the live points
# (and the next seed of the material's stream), at most this many times: on a calibration render of smooth solar glass
# (nearly all of its light in glints) 100 live points stalled from two seeds, where 200 finished
STALL_RESTARTS = 2
BLOCK = 256  # sets per model evaluation (each set at its own geometry rows)


def predicted(model: LightCurveModel, theta: np.ndarray) -> dict[str, np.ndarray]:
    """{flux, dolp, aop_deg: (S, T)} the model's values for rows ``theta`` (NaN DoLP and AoP where no light)."""
    s0, s1, s2 = np.concatenate([model.stokes(theta[i : i + BLOCK]) for i in range(0, len(theta), BLOCK)], axis=1)
    dolp, aop = linear_polarization(s0, s1, s2)
    return {"flux": s0, "dolp": dolp, "aop_deg": aop}


def pointwise_log_likelihood(model: LightCurveModel, curve, observables: list[str], theta: np.ndarray) -> np.ndarray:
    """(S, M) the log-likelihood of each measured number (observables in order, then times) at rows ``theta``
    (``light_curve_likelihood.pointwise``)."""
    return pointwise(curve, observables, predicted(model, theta))


@dataclass
class MaterialFit:
    """One candidate's posterior: ``names``, ``samples`` (equally weighted draws, D), the ELPD-LOO record (``loo``:
    elpd_loo, elpd_loo_se, p_loo, pareto_k, pointwise), nested sampling's ``log_evidence`` (ln Z), its weighted
    points' ``effective_draws`` and its ``likelihood_calls``, the posterior-predictive bands {observable: (3, T)
    5/50/95 %}, ``seconds``, the ``restarts`` a stalled exploration took (``STALL_RESTARTS``), the attitude mode
    the exploration missed and a second run sampled (``fit_material``: its attitude, share of the posterior and a
    finding in words; None where there was none), and whether an exploration that added no shell was ended where it
    stood (its ln Z and draws then rough)."""

    material: str
    description: str
    names: list[str]
    samples: np.ndarray
    loo: dict
    log_evidence: float
    effective_draws: float
    likelihood_calls: int
    bands: dict
    seconds: float
    restarts: int = 0
    added_attitude: dict | None = None
    exploration_ended_early: bool = False

    def save(self, path, key: str) -> None:
        """This fit in one .npz file (written whole or not at all), labelled with ``key`` (what it was fitted to)."""
        from ..io.atomic import atomic_path

        scalars = {"material": self.material, "description": self.description, "names": self.names, "key": key,
                   "log_evidence": self.log_evidence, "effective_draws": self.effective_draws,
                   "likelihood_calls": self.likelihood_calls,
                   "seconds": self.seconds, "restarts": self.restarts, "added_attitude": self.added_attitude,
                   "exploration_ended_early": self.exploration_ended_early,
                   "loo": {k: v for k, v in self.loo.items() if np.ndim(v) == 0 or k == "pareto_k_bad"}}
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
                           scalars["log_evidence"], scalars["effective_draws"], scalars["likelihood_calls"], bands, scalars["seconds"],
                           scalars.get("restarts", 0), scalars.get("added_attitude"),
                           scalars.get("exploration_ended_early", False))
        except (OSError, ValueError, KeyError, EOFError):
            return None

    def summary(self) -> dict:
        """{parameter: {median, q05, q95}} over the posterior draws."""
        q = np.percentile(self.samples, [50, 5, 95], axis=0)
        return {n: {"median": float(q[0, j]), "q05": float(q[1, j]), "q95": float(q[2, j])} for j, n in enumerate(self.names)}


def fit_material(model: LightCurveModel, curve, observables: list[str], rng: np.random.Generator, live: int = 500,
                 progress: bool = False) -> MaterialFit:
    """``model``'s posterior given ``curve``'s ``observables`` and its evidence ln Z: nested sampling (nautilus,
    ``live`` live points, the likelihood in blocks), whose shells cover the whole prior and so every mode it resolves.
    Where the draws miss an attitude mode (``attitude_modes``: a search of the whole prior), a second run samples the
    angles within ``BOX_DEG`` of it, and the two are joined over that partition of the prior (``_joined``)."""
    from ..infer.engines.nested import kish_draws
    from ..infer.engines.stall_guard import CallClock

    start = time.perf_counter()
    calls = {"sets": 0, "next": 20000}
    clock = CallClock()
    name = model.material.name

    def log_likelihood(theta):
        clock.tick()
        theta = np.atleast_2d(theta)
        out = pointwise_log_likelihood(model, curve, observables, theta).sum(axis=1)
        calls["sets"] += len(theta)
        if progress and calls["sets"] >= calls["next"]:
            calls["next"] += 20000
            print(f"  {name}: {calls['sets']} likelihood evaluations, {time.perf_counter() - start:.0f} s",
                  file=sys.stderr)
        return np.where(np.isfinite(out), out, -1e300)  # nautilus needs finite numbers

    run = _nested(model, log_likelihood, _rescaling(model), live, rng, clock, f"material {name}")
    kept = _equal_draws(run, rng)
    ll = pointwise_log_likelihood(model, curve, observables, kept)
    missed = _unsampled_attitude(model, curve, observables, kept, ll.sum(axis=1) + model.log_prior(kept), rng)
    added = None
    if missed is not None:
        if progress:
            print(f"  {name}: an attitude ({attitude_words(missed.attitude)} deg) outside every draw fits "
                  f"{'far better' if missed.far_better else 'about as well'}; sampling it on its own",
                  file=sys.stderr)
        box = _mode_box(model, missed.attitude)
        second = _nested(model, log_likelihood, _rescaling(model, box), live, rng, clock,
                         f"material {name}, its second attitude")
        run, added = _joined(model, run, second, box, missed)
        kept = _equal_draws(run, rng)
        ll = pointwise_log_likelihood(model, curve, observables, kept)
    labels = [f"{observable}[{t:%H:%M:%S}]" for observable in observables for t in curve.times_utc]
    record = loo(az.from_dict(posterior={n: kept[None, :, j] for j, n in enumerate(model.names)},
                              log_likelihood={"y": ll[None]}, coords={"obs_id": labels}, dims={"y": ["obs_id"]}))
    return MaterialFit(name, model.material.description, list(model.names), kept, record, run.log_z,
                       kish_draws(run.log_mass), run.calls, _bands(model, curve, kept[:200], rng),
                       time.perf_counter() - start, run.restarts, added, run.exploration_ended_early)


@dataclass
class _Run:
    """Weighted points of nested sampling: ``log_mass`` each point's ln share of the evidence (its normalised weight
    times Z), ``log_z`` their ln sum, the likelihood ``calls``, the ``restarts`` of stalled explorations, and whether
    an exploration was ended where it stood (``infer.engines.nested.explore_then_sample``)."""

    points: np.ndarray
    log_mass: np.ndarray
    log_z: float
    calls: int
    restarts: int
    exploration_ended_early: bool = False


def _rescaling(model: LightCurveModel, box: np.ndarray | None = None):
    """The map from nautilus's unit cube to the prior; with ``box`` ((3, 2) deg), the attitude angles uniform within
    it instead (the prior restricted to the box: the angles' priors are uniform)."""
    angles = [model.names.index(a) for a in ANGLES] if box is not None else []

    def rescale(u):
        columns = [p.rescale(u[:, j]) for j, p in enumerate(model.priors)]
        for k, j in enumerate(angles):
            columns[j] = box[k, 0] + u[:, j] * (box[k, 1] - box[k, 0])
        return np.column_stack(columns)

    return rescale


def _nested(model: LightCurveModel, log_likelihood, rescale, live: int, rng: np.random.Generator, clock,
            what: str) -> _Run:
    """One nested-sampling run to its draws; a stalled exploration starts again from the prior with twice the live
    points (``STALL_RESTARTS``)."""
    from nautilus import Sampler
    from scipy.special import logsumexp

    from ..infer.engines.nested import STUCK_CALLS_PER_LIVE_POINT, explore_then_sample

    for restarts in range(STALL_RESTARTS + 1):
        sampler = Sampler(rescale, log_likelihood, n_dim=model.ndim, n_live=live * 2**restarts, n_networks=1,
                          vectorized=True, seed=int(rng.integers(2**31)))
        try:
            outcome = explore_then_sample(sampler, EFFECTIVE_DRAWS, clock, what)
            break
        except SamplerStalled as stalled:
            if restarts == STALL_RESTARTS:
                raise SamplerStalled(f"{stalled} (it stalled {restarts + 1} times, with up to {live * 2**restarts} live "
                                     "points)") from None
            print(f"  {what}: {stalled}; starting again from the prior with {2 * live * 2**restarts} live points",
                  file=sys.stderr)
    points, log_w, _ = sampler.posterior()
    log_z = float(sampler.log_z)
    if not outcome.explored:
        print(f"  {what}: the exploration added no shell in {STUCK_CALLS_PER_LIVE_POINT} likelihood calls per live point "
              "and was ended where it stood; its ln Z and draws are rough", file=sys.stderr)
    return _Run(points, log_w - logsumexp(log_w) + log_z, log_z, int(sampler.n_like), restarts, not outcome.explored)


def _equal_draws(run: _Run, rng: np.random.Generator) -> np.ndarray:
    """Equally weighted draws of a run's points, shuffled."""
    from ..infer.engines.nested import replicate_draws

    kept = run.points[replicate_draws(run.points, run.log_mass, rng, min(DRAWS_FOR_LOO, len(run.points)))]
    rng.shuffle(kept)
    return kept


def _mode_box(model: LightCurveModel, attitude: dict) -> np.ndarray:
    """(3, 2) the angles within ``attitude_modes.BOX_DEG`` of ``attitude``, inside the prior."""
    from .attitude_modes import BOX_DEG

    return np.array([[max(lo, attitude[a] - BOX_DEG), min(hi, attitude[a] + BOX_DEG)]
                     for a, (lo, hi) in zip(ANGLES, _angle_bounds(model))])


def _angle_bounds(model: LightCurveModel) -> np.ndarray:
    """(3, 2) the attitude angles' prior bounds (deg)."""
    return np.array([model.priors[model.names.index(a)].bounds for a in ANGLES], float)


def _joined(model: LightCurveModel, first: _Run, second: _Run, box: np.ndarray, mode) -> tuple[_Run, dict]:
    """The posterior over the prior split into the box about a missed mode and the rest: ``first``'s points outside
    the box (its estimate of the rest's mass) and ``second``'s, sampled within it, each weighted by its mass under the
    whole prior (the box's prior probability times its own evidence). Returns the joined run and a record of the mode
    added: its attitude, its share of the posterior, a finding in words."""
    from scipy.special import logsumexp

    columns = [model.names.index(a) for a in ANGLES]
    bounds = _angle_bounds(model)
    inside = np.all((first.points[:, columns] >= box[:, 0]) & (first.points[:, columns] <= box[:, 1]), axis=1)
    box_prior = float(np.sum(np.log((box[:, 1] - box[:, 0]) / (bounds[:, 1] - bounds[:, 0]))))
    second_mass = second.log_mass + box_prior
    log_mass = np.concatenate([first.log_mass[~inside], second_mass])
    log_z = float(logsumexp(log_mass))
    share = float(np.exp(logsumexp(second_mass) - log_z))
    added = {"attitude": mode.attitude, "share": share, "log_posterior": mode.log_posterior,
             "finding": f"an attitude ({attitude_words(mode.attitude)} deg) the exploration missed was sampled on "
                        f"its own and holds {100 * share:.0f} % of the posterior"}
    joined = _Run(np.concatenate([first.points[~inside], second.points]), log_mass, log_z,
                  first.calls + second.calls, first.restarts + second.restarts,
                  first.exploration_ended_early or second.exploration_ended_early)
    return joined, added


def _unsampled_attitude(model: LightCurveModel, curve, observables: list[str], draws: np.ndarray,
                        draws_log_posterior: np.ndarray, rng: np.random.Generator):
    """``attitude_modes.unsampled_mode`` of a fit's draws (an ``AttitudeMode``; None where the draws miss none or the
    attitude is known)."""
    from .attitude_modes import MATERIAL_DRAWS, unsampled_mode

    if model.attitude is not None:
        return None

    def log_posterior(theta):
        return pointwise_log_likelihood(model, curve, observables, theta).sum(axis=1) + model.log_prior(theta)

    own = np.random.default_rng(rng.integers(2**63))  # one draw of the run's stream, however much the check uses
    prior_draws = _rescaling(model)(own.random((MATERIAL_DRAWS, model.ndim)))
    return unsampled_mode(log_posterior, list(model.names), [p.bounds for p in model.priors], draws,
                          draws_log_posterior, prior_draws)


def _bands(model: LightCurveModel, curve, draws: np.ndarray, rng: np.random.Generator) -> dict:
    """{observable: (3, T)} the 5/50/95 % of the posterior predictive (the model plus the file's noise)."""
    return {name: np.percentile(values, [5, 50, 95], axis=0)
            for name, values in replicates(curve, predicted(model, draws), rng).items()}


def _points_carrying_half(difference: np.ndarray) -> int:
    """The fewest measured points whose pointwise ELPD differences make up half the total (0 for none): where it is
    one or two, the paired SE rests on those few and a normal reading of it is unsafe."""
    losses = np.sort(-difference)[::-1]
    total = losses.sum()
    return 0 if total <= 0 else int(np.searchsorted(np.cumsum(losses), 0.5 * total) + 1)


def ranking(fits: list[MaterialFit]) -> list[dict]:
    """The candidates by ELPD-LOO, best first, each with its difference to the best and that difference's paired SE,
    how many points carry half of it, and its ln Z with the difference to the first's (ln of the Bayes factor)."""
    order = sorted(fits, key=lambda f: -f.loo["elpd_loo"])
    top = order[0].loo["pointwise"]
    rows = []
    for f in order:
        d = f.loo["pointwise"] - top
        rows.append({"material": f.material, "elpd": f.loo["elpd_loo"], "elpd_se": f.loo["elpd_loo_se"],
                     "delta_elpd": float(d.sum()), "delta_elpd_se": float(np.sqrt(len(d) * np.var(d))),
                     "log_evidence": f.log_evidence, "delta_log_evidence": f.log_evidence - order[0].log_evidence,
                     "points_carrying_half": _points_carrying_half(d)})
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
                                            "log_evidence": f.log_evidence, "effective_draws": f.effective_draws,
                                            "likelihood_calls": f.likelihood_calls,
                                            "p_loo": f.loo["p_loo"], "pareto_k_max": float(np.max(f.loo["pareto_k"])),
                                            "seconds": f.seconds, "restarts": f.restarts,
                                            "added_attitude": f.added_attitude,
                                            "exploration_ended_early": f.exploration_ended_early} for f in self.fits},
                "times_utc": [t.strftime("%Y-%m-%dT%H:%M:%SZ") for t in self.curve.times_utc],
                "assumptions": self.assumptions}
