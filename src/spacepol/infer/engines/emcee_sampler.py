"""emcee with a vectorised log-probability, ridge-friendly moves, automatic length and resuming.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import json
import sys
import time

import emcee
import numpy as np

from ..buffered_backend import BufferedHDFBackend
from ..engine_result import ESS_TARGET, RHAT_TARGET, EngineResult
from ..sampling_space import SamplingSpace, reaching_a_bound
from .snooker import DESnookerMove


def default_walkers(ndim: int) -> int:
    """32 walkers up to 8 parameters, then 4 per parameter: on small problems more walkers converge in no fewer
    steps and cost more per step (``benchmarks/inversion_speed.py``)."""
    return max(32, 2 * ((4 * ndim + 1) // 2))


def initial_ball(posterior, rng, walkers, init_evaluations=3000):
    """(walkers around the best mode that independent global searches found, the ModeSearch) (``infer.modes``)."""
    from ..modes import search_modes

    modes = search_modes(posterior, rng, evaluations=init_evaluations)
    return ball(posterior, modes.best.theta, walkers, rng), modes


def ball(posterior, centre, walkers, rng):
    """Walkers in a tight ball (1e-3 of each prior width) around ``centre``, each inside the prior
    with a finite log posterior (else at the centre itself)."""
    width = np.diff(posterior.priors.bounds, axis=1).ravel()
    width = np.where(np.isfinite(width), width, 1.0)
    ball_ = centre + 1e-3 * width * rng.standard_normal((walkers, posterior.ndim))
    lo, hi = posterior.priors.bounds.T
    ball_ = np.clip(ball_, lo + 1e-9 * width, hi - 1e-9 * width)
    bad = ~np.isfinite(posterior.log_prob(ball_))
    ball_[bad] = centre
    return ball_


def _kept(sampler, tau):
    if not np.all(np.isfinite(tau)):  # not measurable yet (a walker that never moved): keep the second half
        return sampler.iteration // 2, 1
    burn = int(min(sampler.iteration // 2, np.ceil(3 * np.max(tau))))
    thin = max(1, int(0.5 * np.min(tau)))
    return burn, thin


def _tau(chain) -> np.ndarray:
    """emcee's integrated autocorrelation time over the walkers that moved; inf while a walker has not
    moved at all (its autocorrelation is 0/0, which would make the estimate NaN)."""
    moved = np.all(np.ptp(chain, axis=0) > 0, axis=1)
    if not moved.all():
        return np.full(chain.shape[2], np.inf)
    return emcee.autocorr.integrated_time(chain, tol=0)


def worst_rhat_ess(chains) -> tuple[float, float]:
    """The largest rank-normalised split R-hat and the smallest bulk/tail ESS (ArviZ) of a (chains, draws, D)
    array: what emcee's and NUTS's stopping rules ask for."""
    import arviz as az

    data = az.convert_to_dataset({f"p{j}": chains[:, :, j] for j in range(chains.shape[2])})
    rhat = float(az.rhat(data).to_array().max())
    ess = float(min(az.ess(data, method="bulk").to_array().min(), az.ess(data, method="tail").to_array().min()))
    return rhat, ess


def _rhat_ess(sampler, tau, space):
    """On the declared parameters (what the report shows: R-hat's folded part and tau's estimate differ between
    coordinates), walkers as chains."""
    burn, thin = _kept(sampler, tau)
    chain = space.to_theta(sampler.get_chain(discard=burn, thin=thin))  # (draws, walkers, D)
    return worst_rhat_ess(chain.transpose(1, 0, 2))




def starting_points(posterior, rng, count: int, initial=None):
    """((count, D) starting parameter vectors, the ModeSearch behind them or None): ``initial`` as given, prior
    draws for "prior", or by default a small ball around the best mode of the start-point searches."""
    if initial is None:
        return initial_ball(posterior, rng, count)
    if isinstance(initial, str) and initial == "prior":
        return posterior.priors.sample(rng, count), None
    return np.atleast_2d(np.asarray(initial, float)), None


def ridge_moves() -> list:
    """The engine's proposal mix: differential evolution (80 %) and DE snooker (20 %), which follow long ridges."""
    return [(emcee.moves.DEMove(), 0.8), (DESnookerMove(), 0.2)]


def _store(path, **attributes) -> None:
    """Settings the chain file carries, so that a resumed run uses and reports the same: the sampler's coordinates
    (``spacepol_space``) and the start-point searches' modes (``spacepol_start_search``, JSON)."""
    import h5py

    with h5py.File(path, "a") as f:
        for name, value in attributes.items():
            f.attrs[name] = value


def _stored(path, name: str, default=None):
    import h5py

    with h5py.File(path, "r") as f:
        return f.attrs.get(name, default)


def _tau_at(sampler, iteration: int, space) -> np.ndarray:
    """The integrated autocorrelation time of the first ``iteration`` steps (what an uninterrupted run
    computed when it stood there), so a resumed run takes the same decisions."""
    return _tau(space.to_theta(sampler.get_chain()[:iteration]))


def sample_emcee(posterior, rng: np.random.Generator, walkers: int | None = None, max_steps: int = 20000,
                 tau_multiple: float = 50.0, check_every: int = 500, min_steps: int = 1000,
                 backend_path=None, progress: bool = True, model_name: str = "", seed: int | None = None,
                 initial=None, rhat_target: float = RHAT_TARGET, ess_target: float = ESS_TARGET, space=None,
                 enough=None) -> EngineResult:
    """``space``: the coordinates the walkers move in (default ``SamplingSpace``, the logit of each prior's CDF;
    ``DeclaredSpace`` is the declared parameters, the baseline of ``benchmarks/inversion_speed.py``). ``enough``: for a
    caller that needs one estimate rather than the whole posterior, ``enough(step, chain)`` at each check (the chain
    after burn-in, declared parameters, (steps, walkers, D)) may end the run before convergence (``elpd_settled``);
    ``info["stopped_early"]`` then says so, and R-hat and ESS are reported as they stand."""
    start = time.perf_counter()
    ndim = posterior.ndim
    walkers = walkers or default_walkers(ndim)
    backend, resumed = _open_chain(backend_path, rng, walkers, ndim)

    # every step evaluates half the ensemble: that size is compiled as it is (padding 18 walkers to the next
    # compiled size, 64, tripled the cost of a full-Mueller step); the whole ensemble (the start) goes in two halves
    if hasattr(getattr(posterior, "likelihood", None), "exact_sizes"):
        posterior.likelihood.exact_sizes.add(walkers // 2)
    space, initial, start_search, random_state = _chain_start(posterior, rng, walkers, initial, space, backend_path,
                                                              resumed, progress)
    log_prob = space.log_prob(posterior)
    sampler = emcee.EnsembleSampler(walkers, ndim, log_prob, vectorize=True, moves=ridge_moves(), backend=backend)
    # called directly, not through emcee's wrapper, which prints every walker's position and a traceback before it
    # re-raises anything the function raises (Ctrl-C included), under the command line's one line
    sampler.log_prob_fn = log_prob
    tau, previous_tau, capped, stopped_early = np.full(ndim, np.inf), None, True, False

    def converged(tau, previous_tau):
        settled = (previous_tau is not None and np.all(np.isfinite(tau)) and np.all(np.isfinite(previous_tau))
                   and np.all(np.abs(previous_tau - tau) < 0.05 * tau))
        long_enough = sampler.iteration >= max(min_steps, tau_multiple * np.max(tau)) and settled
        rhat, ess = (_rhat_ess(sampler, tau, space) if long_enough else (np.nan, np.nan))
        return long_enough and rhat <= rhat_target and ess >= ess_target, long_enough, rhat, ess

    def caller_has_enough(tau) -> bool:
        if enough is None or sampler.iteration < min_steps:
            return False
        burn, _ = _kept(sampler, tau)
        return bool(enough(sampler.iteration, space.to_theta(sampler.get_chain(discard=burn))))

    if resumed:
        state = None
        tau, previous_tau, capped, stopped_early, max_steps = _resume(sampler, space, check_every, max_steps, converged,
                                                                      caller_has_enough, progress, backend_path)
    else:
        sampler.random_state = random_state
        state = space.to_z(initial)

    while sampler.iteration < max_steps:
        target = min(max_steps, (sampler.iteration // check_every + 1) * check_every)
        try:
            state = sampler.run_mcmc(state, target - sampler.iteration, progress=False)
        finally:  # interrupted too: the steps taken so far go to the file, so the same command continues them
            if backend is not None:
                backend.flush()
        tau = _tau_at(sampler, sampler.iteration, space)
        ok, long_enough, rhat, ess = converged(tau, previous_tau)
        previous_tau = tau
        if progress:
            _say_step(sampler, max_steps, tau, tau_multiple, f", R-hat {rhat:.3f}, ESS {ess:.0f}" if long_enough else "")
        if ok:
            capped = False
            break
        if sampler.iteration < max_steps and caller_has_enough(tau):
            stopped_early, capped = True, False
            if progress:
                print(f"  step {sampler.iteration:6d}: stopped, the caller's estimate has settled", file=sys.stderr)
            break
    if not np.all(np.isfinite(tau)):  # no block was run here (a finished chain): measure what is stored
        tau = _tau_at(sampler, sampler.iteration, space)

    return _emcee_result(posterior, sampler, space, tau, walkers, capped, resumed, tau_multiple, stopped_early,
                         start_search, model_name, seed, start)


def _open_chain(backend_path, rng: np.random.Generator, walkers: int, ndim: int):
    """(the chain file's backend or None, whether it holds steps to continue); a chain of another shape is one line."""
    from ..chain_file import chain_iterations, random_state_readable, replace_random_state

    if backend_path is None:
        return None, False
    stored = chain_iterations(backend_path)  # ChainFileError (one line, the remedy) if damaged
    if stored > 0 and not random_state_readable(backend_path):
        # killed while emcee rewrote its random state: the steps are intact, so continue from them with a
        # state drawn from this run's generator (reproducible from --seed and the step count)
        replace_random_state(backend_path, np.random.RandomState(int(rng.integers(2**32)) ^ stored).get_state())
    backend = BufferedHDFBackend(str(backend_path), name="mcmc")
    if stored == 0:
        backend.reset(walkers, ndim)
        return backend, False
    if tuple(backend.shape) != (walkers, ndim):
        from ...errors import SpacepolError

        raise SpacepolError(f"{backend_path}: holds a chain of shape {tuple(map(int, backend.shape))}, this run "
                            f"needs {(walkers, ndim)}; use another --out or --restart")
    return backend, True


def _chain_start(posterior, rng, walkers, initial, space, backend_path, resumed, progress):
    """(the sampling space, the walkers' start in theta, the start-point search's record, emcee's random state): from
    the chain file where the chain resumes, else from a start-point search (its modes recorded in the file)."""
    if resumed:
        space = space or SamplingSpace.from_name(posterior.priors, str(_stored(backend_path, "spacepol_space",
                                                                               SamplingSpace.family)))
        stored_search = _stored(backend_path, "spacepol_start_search")
        return space, initial, None if stored_search is None else json.loads(str(stored_search)), None
    start_search = None
    random_state = np.random.RandomState(int(rng.integers(2**32))).get_state()
    initial, modes = starting_points(posterior, rng, walkers, initial)
    if modes is not None:
        start_search = modes.to_json() | {"findings": modes.findings()}
        if progress:
            for line in modes.findings():
                print(f"  {line}", file=sys.stderr)
    if space is None:  # parameters whose bound the posterior reaches (from the walkers' median) keep their own
        space = SamplingSpace(posterior.priors, declared=reaching_a_bound(posterior, np.median(initial, axis=0)))
    if backend_path is not None:
        extra = {} if start_search is None else {"spacepol_start_search": json.dumps(start_search)}
        _store(backend_path, spacepol_space=space.name, **extra)
    return space, initial, start_search, random_state


def _emcee_result(posterior, sampler, space, tau, walkers, capped, resumed, tau_multiple, stopped_early, start_search,
                  model_name, seed, start) -> EngineResult:
    """The chain after burn-in, thinned by tau (every draw where the caller's check stopped it), as an EngineResult."""
    tau_max = float(np.max(tau))
    burn, thin = _kept(sampler, tau)
    if stopped_early:
        # every draw after burn-in, as the caller's check read them, so that what it reports comes from the draws
        # the check saw settle
        thin = 1
    chain_z = sampler.get_chain(discard=burn, thin=thin)
    log_prob = space.log_posterior_theta(chain_z, sampler.get_log_prob(discard=burn, thin=thin))
    chain = space.to_theta(chain_z)
    flat_i = np.unravel_index(np.argmax(log_prob), log_prob.shape)
    best = chain[flat_i]
    info = {
        "steps": int(sampler.iteration), "walkers": walkers, "burn_in": burn, "thin": thin,
        "tau": [float(t) for t in tau], "tau_max": tau_max,
        "acceptance": float(np.mean(sampler.acceptance_fraction)), "capped": capped,
        "resumed": resumed, "moves": "DE", "space": space.name, "tau_multiple": tau_multiple,
        "stopped_early": stopped_early,
    }
    if start_search is not None:
        info["start_search"] = start_search
    return EngineResult(
        method="emcee", model=model_name, names=list(posterior.names),
        best=dict(zip(posterior.names, map(float, best))), objective=float(-log_prob[flat_i]),
        objective_name="negative_log_posterior", n_evaluations=int(sampler.iteration * walkers),
        seconds=time.perf_counter() - start, seed=-1 if seed is None else seed,
        samples=chain, log_prob=log_prob, info=info,
    )


def _say_step(sampler, max_steps, tau, tau_multiple, extra: str) -> None:
    """One progress line of the chain at a check."""
    print(f"  step {sampler.iteration:6d}/{max_steps}: tau_max {np.max(tau):7.1f} "
          f"(need {tau_multiple:.0f} tau = {tau_multiple * np.max(tau):7.0f} steps), "
          f"acceptance {np.mean(sampler.acceptance_fraction):.2f}{extra}", file=sys.stderr)


def _resume(sampler, space, check_every, max_steps, converged, caller_has_enough, progress, backend_path):
    """Where a stored chain continues: (tau, previous tau, capped, stopped early, the step cap). A chain stopped right
    at a check takes that check's decision again (converged, its caller's estimate settled, or at the cap: no further
    steps); else it runs on with the tau an uninterrupted run would hold at its next check."""
    tau, capped, stopped_early = np.full(sampler.ndim, np.inf), True, False
    done = sampler.iteration
    at_check = done % check_every == 0 or done >= max_steps
    before = (done - check_every if done % check_every == 0 else done // check_every * check_every) if at_check \
        else done // check_every * check_every  # the check whose tau an uninterrupted run holds next
    previous_tau = _tau_at(sampler, before, space) if before >= check_every else None
    if at_check:
        tau = _tau_at(sampler, done, space)
        ok, *_ = converged(tau, previous_tau)
        stopped_early = bool(not ok and done < max_steps and caller_has_enough(tau))
        if ok or stopped_early or done >= max_steps:
            capped = not ok and not stopped_early
            if progress:
                how = "converged" if ok else "its caller's estimate settled" if stopped_early else "at the step cap"
                print(f"  the chain in {backend_path} is complete ({done} steps, {how}); writing the report",
                      file=sys.stderr)
            max_steps = done  # no further steps
        previous_tau = tau
    if progress and done < max_steps:
        print(f"  resuming the chain in {backend_path} at step {done}", file=sys.stderr)
    return tau, previous_tau, capped, stopped_early, max_steps
