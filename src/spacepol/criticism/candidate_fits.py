"""diagnose's fits of its candidate models: each built, searched and refitted on its own, in this process or in
worker processes at once (``CandidateFits``), with the same answer either way.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import zlib
from concurrent.futures import as_completed
from typing import Iterator

import numpy as np

from ..infer import elpd_settled
from ..infer.engines.base import SAMPLER, Engine
from ..infer.engine_registry import engines
from ..infer.inversion import invert
from ..infer.optimum import multistart, screen_optimum
from ..infer.posterior import Posterior
from ..physics.registry import registry
from .changes import start_points

# diagnose's fits compare predictive accuracy (ELPD-LOO), which needs enough independent draws (ESS >= 400, R-hat
# <= 1.01, both still required), not the 50 tau a run's reported posterior waits for (emcee's advice for a stable
# tau itself); how far its delta ELPD lies from a 50-tau chain's is not yet measured
ELPD_TAU_MULTIPLE = 20.0
# PSIS-LOO of a candidate from at most this many draws (Vehtari et al. recommend >= 2,000 for a stable k-hat): a
# converged chain keeps several times more, whose pointwise log-likelihood and LOO would dominate each refit
ELPD_DRAWS = 2000

POSTERIOR_METHODS = ("laplace", "emcee")


def model_key(model) -> tuple:
    """What identifies a model among diagnose's candidates (its ``searched`` maxima, the posteriors kept): its
    effects in order and its wavelengths."""
    return model.name, tuple(getattr(model, "wavelengths", ()))


def task_seed(root: int, kind: str, key: tuple) -> int:
    """The seed of one task (``screen``, ``leader``, ``refit``) of the model ``key`` (``model_key``) under a root seed:
    independent streams for different tasks and models (numpy's SeedSequence), the same for the same ones."""
    entropy = [root, zlib.crc32(f"{kind}|{key!r}".encode())]
    return int(np.random.SeedSequence(entropy).generate_state(1, np.uint64)[0] >> np.uint64(1))


def _build(data, model, observables, priors, check: bool = True):
    """The posterior of ``model`` with those prior overrides that name its parameters (or nuisances); ``check``:
    ``Posterior.build``'s (False: its likelihood is compiled at first use, ``Posterior.ensure_checked``)."""
    probe = Posterior.build(data, model, observables=observables, check=False)
    own = {p.name for p in probe.priors.parameters}
    overrides = {k: v for k, v in (priors or {}).items() if k in own}
    post = Posterior.build(data, model, overrides, observables=observables, check=False) if overrides else probe
    return post.ensure_checked() if check else post


def fit_for_elpd(posterior: Posterior, centre, seed: int, max_steps: int, posterior_method: str = "laplace"):
    """The Result whose pointwise PSIS-LOO diagnose compares, started at ``centre`` (an optimum). "laplace": the
    Laplace approximation corrected by importance sampling (the registry's ``laplace`` engine), where its checks trust
    it, else emcee (why not: ``summary.laplace_refused``; stopped before convergence where the ELPD-LOO of its
    two halves agree, ``elpd_settled``); "emcee": emcee always. Where the approximation is trusted the two agree
    at a fraction of emcee's cost (``benchmarks/laplace_vs_emcee.py``)."""
    if posterior_method not in POSTERIOR_METHODS:
        raise ValueError(f"posterior_method {posterior_method!r}: one of {', '.join(POSTERIOR_METHODS)}")
    refusal = None
    if posterior_method == "laplace":
        inv, refusal = engines.get("laplace").approximate(posterior, centre, seed=seed, draws=ELPD_DRAWS)
        if inv is not None:
            return inv
    inv = invert(posterior, seed=seed, max_steps=max_steps, progress=False, centre=centre,
                 tau_multiple=ELPD_TAU_MULTIPLE, max_pointwise_draws=ELPD_DRAWS, elpd_tolerance=elpd_settled.TOLERANCE)
    if refusal:  # why emcee: the Laplace approximation's failed checks
        inv.summary.laplace_refused = refusal
    return inv


class DiagnosePosterior(Engine):
    """diagnose's posterior of one model as a sampler (for calibration): the optimum of ``find_optimum``, then
    ``fit_for_elpd`` (Laplace-IS where its checks trust it, else emcee stopped where its ELPD-LOO settles).
    ``ran`` lists, per call, the engine that gave the draws."""

    name, kind = "diagnose-posterior", SAMPLER
    description = "diagnose's default posterior: Laplace-IS where trusted, else emcee"

    def __init__(self, variant: str | None = None, max_steps: int = 8000):
        super().__init__(variant)
        self.max_steps = max_steps
        self.ran: list[str] = []

    def run(self, posterior, rng, progress: bool = False):
        """The Result's draws; the engine that ran is appended to ``ran``."""
        from ..infer.optimum import find_optimum

        seed = int(rng.integers(2**31))
        _, centre = find_optimum(posterior, np.random.default_rng(seed))
        inv = fit_for_elpd(posterior, centre, seed, self.max_steps)
        self.ran.append(inv.summary.diagnostics["engine"])
        return inv.draws


def _screen(post, change, base_optimum: dict, evaluations: int, seed: int) -> tuple[float, dict]:
    new = [j for j, name in enumerate(post.priors.names) if name not in base_optimum]
    best, theta = screen_optimum(post, np.random.default_rng(seed), start_points(base_optimum, change, post), new,
                                 evaluations)
    return float(best), dict(zip(post.priors.names, map(float, theta)))


def _leader(post, seed: int) -> tuple[float, np.ndarray]:
    value, theta = multistart(post, np.random.default_rng(seed))
    return float(value), np.asarray(theta, float)


TASKS = {"screen": _screen, "leader": _leader, "refit": fit_for_elpd}
# the tasks whose result is a function of the model, its arguments and its seed alone (the same for the same model
# within one ``CandidateFits``): done once, however often the rounds ask (a screening's answer depends on where it
# starts, kept already by diagnose's ``searched``)
REMEMBERED = ("leader", "refit")


def task_key(kind: str, model, args: tuple) -> tuple | None:
    """What identifies a task of ``REMEMBERED`` kind among those done (None for the others): its kind, the model
    (``model_key``) and its arguments, arrays by their bytes."""
    if kind not in REMEMBERED:
        return None
    return kind, model_key(model), tuple(np.asarray(a, float).tobytes() if isinstance(a, np.ndarray) else a
                                         for a in args)

_WORKER_KEEPS = 4  # posteriors a worker keeps
_WORKER: dict = {}  # in a worker process: the data and the fitting settings, sent once


def _start_worker(data, observables, priors, small_calls: bool | None) -> None:
    if small_calls is not None:  # the settings the calling process chose (None: it chose none)
        from .._runtime import configure_process

        configure_process(small_calls=small_calls)
    _WORKER.update(data=data, observables=observables, priors=priors)


def _in_worker(kind: str, model, args: tuple):
    # the last few models' posteriors are kept for their next tasks (a candidate's leader search and refit follow its
    # screening): each new one compiles its likelihood again; a few only, as every compiled one kept slows the process
    posteriors = _WORKER.setdefault("posteriors", {})
    key = model_key(model)
    if key not in posteriors:
        posteriors[key] = _build(_WORKER["data"], model, _WORKER["observables"], _WORKER["priors"])
        while len(posteriors) > _WORKER_KEEPS:
            posteriors.pop(next(iter(posteriors)))
    post = posteriors[key]
    out = TASKS[kind](post, *args)
    if kind == "refit":
        out.posterior = None  # not picklable; the caller's own posterior replaces it
    return out


class CandidateFits:
    """Runs diagnose's per-candidate tasks (``screen``, ``leader``, ``refit``) for one data set, fitting settings
    (observables, prior overrides) and ``workers`` processes (1: in this process). Use as a context manager, or
    ``close`` it; the worker processes start on the first parallel call."""

    def __init__(self, data, observables=None, priors: dict | None = None, workers: int = 1):
        self.data, self.observables, self.priors = data, observables, priors
        self.workers = max(1, int(workers))
        self._pool, self._root = None, None
        self._done: dict = {}  # {task_key: result} of the deterministic tasks (``REMEMBERED``) run so far
        self._recalled: set = set()  # the ids of those results handed out again

    def posterior(self, model) -> Posterior:
        """The candidate's posterior in this process, not checked (``Posterior.ensure_checked``) until a task runs
        here: the check compiles its likelihood (seconds for a full-Mueller model), which a worker process
        compiles again, and a candidate whose maximum is known already may never be evaluated here at all. Not kept
        either: 61 compiled candidate posteriors held in one process made every later evaluation 1.3x slower
        (Python's collector walking twice the objects), more than their compilations would cost again."""
        return _build(self.data, model, self.observables, self.priors, check=False)

    def run(self, kind: str, jobs: list[tuple], rng: np.random.Generator) -> Iterator[tuple[int, object]]:
        """(index, result) per job, as jobs finish; a job is (model, posterior in this process, args...) and gets as
        its ``seed`` argument ``task_seed`` of its kind and model (the root drawn from ``rng`` at the first call). A
        leader search or refit done before by this object (``task_key``) is not done again: its result is returned."""
        if self._root is None:
            self._root = int(rng.integers(2**63))
        keys = [task_key(kind, job[0], job[2:]) for job in jobs]
        todo = []
        for i, key in enumerate(keys):
            if key in self._done:
                self._recalled.add(id(self._done[key]))
                yield i, self._done[key]
            else:
                todo.append(i)
        for j, out in self._run(kind, [jobs[i] for i in todo]):
            if keys[todo[j]] is not None:
                self._done[keys[todo[j]]] = out
            yield todo[j], out

    def recalled(self, result) -> bool:
        """Whether ``result`` was handed out again by ``run`` (a task done before), not done for that call."""
        return id(result) in self._recalled

    def _run(self, kind: str, jobs: list[tuple]) -> Iterator[tuple[int, object]]:
        seeds = [task_seed(self._root, kind, model_key(job[0])) for job in jobs]
        parallel = self.workers > 1 and len(jobs) > 1 and not any(_from_a_file(job[0]) for job in jobs)
        if not parallel:
            for i, (job, seed) in enumerate(zip(jobs, seeds)):
                yield i, TASKS[kind](job[1].ensure_checked(), *_with_seed(kind, job[2:], seed))
            return
        pool = self._open()
        futures = {pool.submit(_in_worker, kind, job[0], _with_seed(kind, job[2:], seed)): i
                   for i, (job, seed) in enumerate(zip(jobs, seeds))}
        try:
            for future in as_completed(futures):
                i = futures[future]
                out = future.result()
                if kind == "refit":
                    out.posterior = jobs[i][1]
                yield i, out
        finally:
            for future in futures:
                future.cancel()

    def _open(self):
        if self._pool is None:
            from .._runtime import configured, spawned_pool

            self._pool = spawned_pool(self.workers, initializer=_start_worker,
                                      initargs=(self.data, self.observables, self.priors, configured()))
        return self._pool

    def close(self) -> None:
        """Stop the worker processes."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _with_seed(kind: str, args: tuple, seed: int) -> tuple:
    """The task's arguments with its seed where the task takes it (a refit keeps diagnose's own seed)."""
    return args if kind == "refit" else (*args, seed)


def _from_a_file(model) -> bool:
    """Whether an effect of ``model`` was loaded from a user's file (``path.py:Name``)."""
    return any(".py:" in registry.sources.get(e.name, "") for e in getattr(model, "effects", ()))
