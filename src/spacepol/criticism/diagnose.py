"""What is missing or wrong in a model: screen every change (add, replace, remove), confirm the leaders.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import SpacepolError
from ..infer.inference_data import median_fit
from ..infer.optimum import find_optimum
from ..infer.posterior import Posterior
from ..physics.model import Model
from ..physics.registry import registry
from .candidate_fits import CandidateFits, model_key
from .changes import BLIND_REASON, blind_changes, changes, separating_observables
from .criteria import CRITERIA, CRITERION, MIN_DELTA_ELPD, Criterion, significant
from .explain import (conclusion, posterior_quality, posterior_words, refitted_entry, signatures, tie_words,
                      tied, unrefitted_entry)
from .records import CandidateFit, DiagnosisRecord


def check_prior_names(data, model: Model, priors: dict, observables=None, candidates=None) -> None:
    """Every overridden prior must belong to the base model or to one of the candidates."""
    known = {p.name for p in Posterior.build(data, model, observables=observables).priors.parameters}
    for change in changes(model, data, candidates):
        known |= {p.name for p in change.model.parameters}
    unknown = sorted(set(priors or {}) - known)
    if unknown:
        raise SpacepolError(f"--prior: no parameter(s) {', '.join(unknown)} in {model.name} or any candidate effect")


def _global_optimum(posterior, rng, budget, seeds=None):
    value, theta = find_optimum(posterior, rng, evaluations=budget, seeds=seeds)
    return value, dict(zip(posterior.priors.names, theta))


def _vector(values: dict, posterior) -> np.ndarray:
    return np.array([values[n] for n in posterior.priors.names], float)


@dataclass
class _Run:
    """What the stages of one diagnosis share: the settings, the shared fits, the base model's posterior, fit and
    optimum, and the clock."""

    data: object
    fits: CandidateFits
    rng: np.random.Generator
    seed: int
    progress: bool
    max_steps: int
    posterior_method: str
    confirm: tuple
    criterion: Criterion
    searched: dict
    screening_evaluations: int
    clock: dict
    base_post: Posterior = None
    base: object = None
    base_best: float = 0.0
    base_optimum: dict = None
    blind: list = field(default_factory=list)
    board: dict = field(default_factory=dict)  # {change label: its CandidateFit as it stands}

    def update(self, label: str, **fields) -> CandidateFit:
        """The change ``label``'s record with ``fields`` replaced (records are immutable): the new one."""
        self.board[label] = replace(self.board[label], **fields)
        return self.board[label]

    def say(self, text: str) -> None:
        """A progress line with the seconds since the start, where progress is on."""
        if self.progress:
            _say(f"{text} ({time.perf_counter() - self.clock['start']:.0f} s)")

    @property
    def base_loo(self) -> np.ndarray:
        """The base fit's pointwise ELPD-LOO."""
        return self.base.loo["pointwise"]


def diagnose(data, model: Model, rng: np.random.Generator, seed: int = 0, observables=None, candidates=None,
             top: int = 3, screening_evaluations: int = 4000, max_steps: int = 8000, progress: bool = True,
             priors: dict | None = None, base=None, confirm=(), simplifications: int = 0,
             posterior_method: str = "laplace", searched: dict | None = None, workers: int = 1,
             fits: CandidateFits | None = None, criterion: str = "loo") -> DiagnosisRecord:
    """Rank the effects missing from ``model``; ``priors`` overrides default priors by parameter name;
    ``base``: a Result of ``model`` on these data already at hand (it is not refitted); ``confirm``:
    change labels refitted whatever their screening gain; ``simplifications``: how many changes with fewer free
    parameters to refit besides (for diagnose --rounds, which may take one when nothing is significant);
    ``posterior_method``: how each fit's posterior is drawn (``fit_for_elpd``); ``searched``: the maxima already
    found for models on these data with these priors ({``model_key``: (max log posterior, optimum by name)}), used
    instead of a search and filled by this call (diagnose --rounds passes one from round to round: removing the
    effect a round added gives back the model it started from, and replacing it gives a model screened then);
    ``workers``: how many candidates are searched and refitted at once, in worker processes (the answer does not
    depend on it: ``candidate_fits``); ``fits``: a ``CandidateFits`` already open for these data (diagnose --rounds
    keeps one for all its rounds), else one is opened and closed here; ``criterion``: what ranks the refitted
    changes and calls them significant, ``loo`` (delta ELPD-LOO > 2 SE and > 4) or ``evidence`` (ln Bayes factor
    > 3 and > 2 x its error; ln Z from Laplace-IS where trusted, else nested sampling). Each ranking entry holds
    both differences where both are known.

    A pipeline: the base fit (``_fit_base``), then ``_screen`` -> ``_select`` -> ``_refit`` -> ``_rank`` ->
    ``_explain``."""
    if criterion not in CRITERION:
        raise SpacepolError(f"--criterion {criterion}: unknown ({', '.join(CRITERIA)})")
    if fits is None:
        with CandidateFits(data, observables, priors, workers) as own:
            return diagnose(data, model, rng, seed=seed, observables=observables, candidates=candidates, top=top,
                            screening_evaluations=screening_evaluations, max_steps=max_steps, progress=progress,
                            priors=priors, base=base, confirm=confirm, simplifications=simplifications,
                            posterior_method=posterior_method, searched=searched, fits=own, criterion=criterion)
    check_prior_names(data, model, priors, observables, candidates)
    run = _Run(data, fits, rng, seed, progress, max_steps, posterior_method, tuple(confirm), CRITERION[criterion],
               {} if searched is None else searched, screening_evaluations, {"start": time.perf_counter()})
    all_candidates = _fit_base(run, model, base, candidates)
    screened = _screen(run, all_candidates)
    to_confirm = _select(run, screened, top, simplifications)
    confirmed = _refit(run, to_confirm)
    return _explain(run, model, screened, _rank(run, confirmed))  # each stage: change labels; ``run.board`` the records


def _fit_base(run: _Run, model: Model, base, candidates) -> list:
    """The base model's optimum (searched once per model and priors) and fit (``base`` where given); the changes to
    screen, those the fitted observables cannot see set aside in ``run.blind``."""
    run.base_post = run.fits.posterior(model)
    if _same_posterior(base, run.base_post):  # compiled already (diagnose --rounds: the last round's lead)
        run.base_post = base.posterior
    run.base_post.ensure_checked()
    if model_key(model) not in run.searched:
        run.searched[model_key(model)] = _global_optimum(run.base_post, run.rng, run.screening_evaluations)
    run.base_best, run.base_optimum = run.searched[model_key(model)]
    all_candidates = changes(model, run.data, candidates)
    # changes the fitted observables cannot see (a DOP estimator's bias on Mueller data) are not screened
    run.blind = blind_changes(all_candidates, run.base_post.likelihood.objects)
    if base is None:
        run.say(f"[base] fitting {model.name} ({len(run.data)} geometries) ...")
        job = (model, run.base_post, _vector(run.base_optimum, run.base_post), run.seed, run.max_steps, run.posterior_method)
        base = dict(run.fits.run("refit", [job], run.rng))[0]  # kept by ``fits`` as the candidates' refits are
    run.base = base
    run.clock["base"] = time.perf_counter()
    return [c for c in all_candidates if c not in run.blind]


def _screen(run: _Run, all_candidates: list) -> list[str]:
    """Every change's maximum log posterior (searched near the base's optimum, or known from ``run.searched``) and
    its gain over the base's: the changes' labels, best first."""
    run.say(f"[base] done; screening {len(all_candidates)} candidate effects")
    if run.blind:
        run.say(f"[screen] not screened: {', '.join(c.label for c in run.blind)} ({BLIND_REASON})")
    posteriors = [run.fits.posterior(change.model) for change in all_candidates]
    unsearched = [i for i, change in enumerate(all_candidates) if model_key(change.model) not in run.searched]

    def screened_line(i: int, done: int) -> None:
        gain = run.searched[model_key(all_candidates[i].model)][0] - run.base_best
        run.say(f"[screen {done}/{len(all_candidates)}] {all_candidates[i].label:<32s} max log posterior gain {gain:9.2f}")

    done = 0
    for i in [i for i in range(len(all_candidates)) if i not in unsearched]:
        done += 1
        screened_line(i, done)
    jobs = [(all_candidates[i].model, posteriors[i], all_candidates[i], run.base_optimum, run.screening_evaluations)
            for i in unsearched]
    for j, found in run.fits.run("screen", jobs, run.rng):
        run.searched[model_key(all_candidates[unsearched[j]].model)] = found
        done += 1
        screened_line(unsearched[j], done)
    for change, post in zip(all_candidates, posteriors):
        best, optimum = run.searched[model_key(change.model)]
        run.board[change.label] = CandidateFit(change, post, float(best - run.base_best), _vector(optimum, post))
    run.clock["screening"] = time.perf_counter()
    return sorted(run.board, key=lambda label: -run.board[label].screening_gain)


def _select(run: _Run, screened: list[str], top: int, simplifications: int) -> list[str]:
    """The changes to refit: the ``top`` screened and their equals, the twins of an addition among them (where the
    fitted observables do not separate the two), the changes asked for (``confirm``) and ``simplifications`` changes
    with fewer free parameters; each starts from the best of its screening and a global multistart. A change asked
    for whose optimum alone decides (``_plugin_decides``) is not refitted."""
    board = run.board
    gain = {label: board[label].screening_gain for label in screened}
    # a candidate whose screening gain equals the leader's may be its twin: confirm it too
    chosen = screened[:top] + [c for c in screened[top:] if top and _close(gain[c], gain[screened[0]])]
    # effects declared twins of a confirmed addition are refitted too: a tie can only be seen between two fits; not
    # where the fitted observables separate the two (``Effect.separated_by``: the full Mueller matrix for an analyser
    # and depolarized light), where the twin is refitted only if its own screening earns it
    fitted = set(run.base_post.likelihood.observable_names)
    twins = {t for c in chosen if board[c].kind == "add" for t in registry.get(board[c].effect).twins
             if not fitted & set(separating_observables(board[c].effect, t))}
    chosen += [c for c in screened if c not in chosen and board[c].kind == "add" and board[c].effect in twins]
    chosen += [c for c in screened if c not in chosen and c in run.confirm]
    # the best simplifications (fewer free parameters) that screening does not rule out: if nothing is
    # significant, diagnose --rounds takes one that predicts as well (Occam)
    simpler = [c for c in screened if c not in chosen and board[c].posterior.ndim < run.base_post.ndim
               and gain[c] > -2 * MIN_DELTA_ELPD]
    chosen += simpler[:simplifications]
    # screening searched near the base model; a refit starts from the best of that and a global multistart
    leaders = dict(run.fits.run("leader", [(board[c].model, board[c].posterior) for c in chosen], run.rng))
    for i, label in enumerate(chosen):
        value, theta = leaders[i]
        if value > gain[label] + run.base_best:
            c = run.update(label, screening_gain=float(value - run.base_best), optimum=theta)
            run.searched[model_key(c.model)] = value, dict(zip(c.posterior.priors.names, theta))
    # changes refitted only because the caller asked (the slot alternatives diagnose --rounds weighs at its end)
    # and that their optima alone already show to differ significantly are not refitted
    asked = [c for c in chosen if c in run.confirm]
    decided = set()
    if asked:
        best = np.array([run.base.draws.best[n] for n in run.base_post.priors.names], float)
        base_pointwise = run.base_post.log_prob_pointwise(best[None, :])[0]
        for label in asked:
            found = _plugin_decides(board[label], base_pointwise, float(run.base.loo.get("p_loo", 0.0)))
            if found:
                run.update(label, **found)
                decided.add(label)
    run.clock["leaders"] = time.perf_counter()
    return [c for c in chosen if c not in decided]


def _refit(run: _Run, to_confirm: list[str]) -> list[str]:
    """The selected changes refitted (their posteriors, pointwise ELPD-LOO and signatures), the best screened
    first; one the best refit so far shows clearly worse (``_dominated``, where the criterion allows) is not refitted
    but weighed again against the final front-runner. Returns the refitted ones."""
    board = run.board
    if to_confirm:
        run.say(f"[confirm] refitting {len(to_confirm)}: {', '.join(to_confirm)}")
    # start at the screening optimum: multimodal candidates (film thickness) keep the mode screening found; the
    # best screened first, so that candidates its refit shows to be clearly worse need no refit of their own
    to_confirm = sorted(to_confirm, key=lambda label: -board[label].screening_gain)
    base_fit = median_fit(run.base.posterior, run.base.draws.flat_samples())
    refitted, dominated = [], []

    def refit(batch: list) -> None:
        jobs = [(board[c].model, board[c].posterior, board[c].optimum, run.seed, run.max_steps, run.posterior_method)
                for c in batch]
        for i, inv in run.fits.run("refit", jobs, run.rng):
            run.update(batch[i], **_refit_fields(inv, run.base, base_fit, run.base_loo))
            refitted.append(batch[i])
            when = "fitted before, the same model from the same start" if run.fits.recalled(inv) else f"{inv.summary.seconds:.0f} s"
            run.say(f"[confirm {len(refitted)}/{len(to_confirm) - len(dominated)}] {batch[i]}: {posterior_words(inv)}, {when}")

    def front_runner():
        return _front_runner([board[c] for c in refitted])

    def clearly_worse(label: str, lead) -> bool:
        found = _dominated(board[label], lead) if lead is not None else None
        if found:
            run.update(label, **found)
        return bool(found)

    def weigh(pending: list) -> list:
        """``pending`` less those the best refit so far shows clearly worse (not the changes asked for)."""
        lead = front_runner() if run.criterion.skips_dominated else None
        skip = [c for c in pending if c not in run.confirm and clearly_worse(c, lead)]
        if skip:
            run.say(f"[confirm] not refitted, clearly worse than {lead.label}: {', '.join(skip)}")
        dominated.extend(skip)
        return [c for c in pending if c not in skip]

    # the best screened alone first, then the rest at once (so the refits do not depend on the number of workers);
    # every skip is weighed again against the final front-runner, the one a tie would be judged against
    refit(to_confirm[:1])
    refit(weigh(to_confirm[1:]))
    while dominated:
        again = [c for c in dominated if front_runner() is None or not clearly_worse(c, front_runner())]
        if not again:
            break
        dominated[:] = [c for c in dominated if c not in again]
        refit(again)
    for c in dominated:
        run.update(c, dominated_by=front_runner().label)
    return [c for c in to_confirm if c not in dominated]


def _refit_fields(inv, base, base_fit, base_loo) -> dict:
    """A refit's Result, pointwise ELPD-LOO, difference to the base with its SE, signatures and significance."""
    diff = inv.loo["pointwise"] - base_loo
    delta, se = float(diff.sum()), float(np.sqrt(len(diff) * np.var(diff)))
    return {"inversion": inv, "pointwise": inv.loo["pointwise"], "delta_elpd": delta, "delta_elpd_se": se,
            "rmse_dop_after": inv.summary.fit["rmse_dop"], "signatures": signatures(base, inv, base_fit),
            "significant": significant(delta, se)}


def _rank(run: _Run, confirmed: list[str]) -> list[CandidateFit]:
    """The refitted changes by the criterion, best first, each with its ln Bayes factor where the evidence is known;
    among the significant changes tied with the best, the one with the fewest free parameters leads."""
    base_evidence = run.criterion.evidence(run.base, run.base_post, run.seed)
    for label in confirmed:
        c = run.board[label]
        own = run.criterion.evidence(c.inversion, c.posterior, run.seed)
        if own is not None and base_evidence is not None:
            c = run.update(label, delta_log_evidence=own[0] - base_evidence[0],
                           delta_log_evidence_error=float(np.hypot(own[1], base_evidence[1])))
        run.update(label, **run.criterion.judged(c))
    ranked = sorted((run.board[label] for label in confirmed), key=run.criterion.order)
    if ranked and ranked[0].significant:
        # changes that fit equally well (tied with the best): the one with fewer free parameters leads
        group = [c for c in ranked if c.significant and (c is ranked[0] or tied(ranked[0], c))]
        simplest = min(group, key=lambda c: (c.posterior.ndim, -c.delta_elpd))
        ranked.remove(simplest)
        ranked.insert(0, simplest)
    run.clock["confirmation"] = time.perf_counter()
    return ranked


def _explain(run: _Run, model: Model, screened: list, confirmed: list) -> DiagnosisRecord:
    """The diagnosis: a ranking entry per refitted change (``refitted_entry``) and per change screened out or not
    refitted (``unrefitted_entry``), the verdict with its ties, the conclusion, and where the time went."""
    ranking = [refitted_entry(c, run.base, run.criterion.note) for c in confirmed]
    done = {c.label for c in confirmed}
    ranking += [unrefitted_entry(run.board[label]) for label in screened if label not in done]
    verdict = "none"
    if confirmed and confirmed[0].significant:
        verdict = confirmed[0].verdict
        ranking[0] = tie_words(ranking[0], confirmed)
    clock, base = run.clock, run.base
    return DiagnosisRecord({"model": model.name, "criterion": run.criterion.name, "fit": base.summary.fit,
                            "base_posterior": posterior_quality(base), "ranking": ranking, "verdict": verdict,
                            "not_screened": [{"change": c.label, "reason": BLIND_REASON} for c in run.blind],
                            "free_parameters": run.base_post.ndim,
                            "residual_structure": base.summary.residual_findings,
                            "conclusion": conclusion(base, confirmed, verdict),
                            "seconds": {"base_fit": clock["base"] - clock["start"],
                                        "screening": clock["screening"] - clock["base"],
                                        "confirmation": clock["confirmation"] - clock["screening"],
                                        "leader_search": clock["leaders"] - clock["screening"],
                                        "total": clock["confirmation"] - clock["start"],
                                        "candidates_screened": len(screened), "candidates_refitted": len(confirmed)}},
                           base, confirmed)


def _close(a: float, b: float) -> bool:
    """Screening gains equal within the optimiser's reach (1 unit of log posterior, or 1 %)."""
    return abs(a - b) < 1.0 + 0.01 * max(abs(a), abs(b))


def _same_posterior(result, posterior) -> bool:
    """Whether ``result`` (a Result or None) holds ``posterior`` itself: the same data object, model, observables and
    priors (a user's own run of the model, with its own priors or data, does not count)."""
    own = getattr(result, "posterior", None)
    if own is None:
        return False
    a, b = own.likelihood, posterior.likelihood
    return (a.data is b.data and model_key(a.model) == model_key(b.model) and a.observables == b.observables
            and own.priors.describe() == posterior.priors.describe())


# the SE of a difference of pointwise log likelihoods at two optima, widened thus to stand in for the LOO difference's
PLUGIN_SE_SLACK = 1.25


def _plugin_decides(c: CandidateFit, base_pointwise: np.ndarray, base_p_loo: float) -> dict | None:
    """Whether candidate ``c`` differs from the base so clearly that its refit cannot change the verdict: the pointwise
    log likelihood at its optimum minus the base's at the base's best draw (``base_pointwise``) sums to d with standard error s, and
    |d| - margin > 2 s x PLUGIN_SE_SLACK and > 4 + margin, margin = the base's p_loo + 2 x the candidate's free
    parameters (``base_p_loo``; ELPD-LOO = plug-in log likelihood - p_loo; the margin bounds the change in p_loo). On PTFE at 0.633 um
    (278 geometries, the eight slot alternatives of a five-effect model) the plug-in sums were within 17 of the
    refitted delta ELPD-LOO, whose p_loo changed by up to 26. Returns the figures (``c``'s fields) where it decides,
    else None."""
    d = c.posterior.log_prob_pointwise(c.optimum[None, :])[0] - base_pointwise
    delta, se = float(d.sum()), float(np.sqrt(len(d) * np.var(d)))
    margin = base_p_loo + 2.0 * c.posterior.ndim
    if abs(delta) - margin > max(2.0 * PLUGIN_SE_SLACK * se, MIN_DELTA_ELPD):
        return {"plugin_delta": delta, "plugin_se": se, "plugin_margin": margin}
    return None


def _front_runner(refitted: list):
    """The refitted candidate a skipped one is weighed against: the best by ELPD-LOO, provided it is significant and
    its posterior converged (else None: an unconverged refit's ELPD is less certain than its SE says)."""
    best = max(refitted, key=lambda c: c.delta_elpd, default=None)
    if best is None or not best.significant or not posterior_quality(best.inversion)["converged"]:
        return None
    return best


def _dominated(c: CandidateFit, lead: CandidateFit) -> dict | None:
    """Whether candidate ``c`` is so clearly worse than the refitted ``lead`` that its refit could neither make it
    lead nor tie: the lead's pointwise ELPD-LOO minus c's pointwise log likelihood at its optimum sums to d with
    standard error s, and d - margin > 2 s x PLUGIN_SE_SLACK and > 4 + margin, margin = 2 x c's free parameters.
    The plug-in log likelihood stands above c's ELPD-LOO (by about its effective number of parameters, p_loo, for a
    regular posterior), so d understates how much worse c predicts; the margin covers a posterior whose LOO density
    exceeds its plug-in one. Its refit starts at the same optimum, so it would weigh the same mode.
    Returns the figures (``c``'s fields) where it decides, else None."""
    d = lead.pointwise - c.posterior.log_prob_pointwise(c.optimum[None, :])[0]
    delta, se = float(d.sum()), float(np.sqrt(len(d) * np.var(d)))
    margin = 2.0 * c.posterior.ndim
    if delta - margin > max(2.0 * PLUGIN_SE_SLACK * se, MIN_DELTA_ELPD):
        return {"dominance_delta": delta, "dominance_se": se, "dominance_margin": margin}
    return None


def _say(text: str) -> None:
    print(f"  {text}", file=sys.stderr, flush=True)


