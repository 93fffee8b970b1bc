"""The ``emcee`` engine, the default sampler: ``invert`` runs emcee (``emcee_sampler``) from an optimum until it
converges, keeps its chain in the output folder under a fingerprint of the run, and continues an interrupted chain."""

from __future__ import annotations

import hashlib
import time
from pathlib import Path

import h5py
import numpy as np

from ...errors import SpacepolError
from ..chain_file import chain_iterations, compact
from ..diagnostics import convergence, loo
from ..draws_result import summarised
from ..elpd_settled import settled
from ..inference_data import to_inference_data
from ..posterior import Posterior
from ..result import Result
from ..sampling_space import SamplingSpace
from .base import SAMPLER, Engine
from .emcee_sampler import ball, default_walkers, sample_emcee


def fingerprint(posterior: Posterior, walkers: int, seed: int, space: str = SamplingSpace.family) -> str:
    """A short hash of what decides a chain (model, priors, observables, data, walkers, seed, sampling space): a stored
    chain resumes only under the same fingerprint."""
    lik = posterior.likelihood
    h = hashlib.sha256()
    h.update(lik.model.name.encode())
    h.update(repr(sorted(posterior.priors.describe().items())).encode())
    h.update(repr(lik.observables).encode())
    h.update(np.ascontiguousarray(np.column_stack([lik.data.theta_i, lik.data.theta_r, lik.data.dphi])).tobytes())
    observed = lik.observed()
    for o in lik.observables:
        h.update(np.ascontiguousarray(observed[o]).tobytes())
    h.update(f"{walkers}:{seed}:{space}".encode())  # the chain file holds the sampler's coordinates
    return h.hexdigest()[:16]


def _check_backend(path: Path, print_: str) -> None:
    if not path.exists():
        return
    chain_iterations(path)  # a damaged file: one line with the remedy
    with h5py.File(path, "r") as f:
        stored = f.attrs.get("spacepol_fingerprint")
    if stored is not None and stored != print_:
        raise SpacepolError(f"{path}: holds the chain of a different run (model, data, priors, walkers or seed); "
                            f"add --restart to start afresh (the old chain is kept as {path.name}.old) or use another --out")


def _stamp_backend(path: Path, print_: str) -> None:
    with h5py.File(path, "a") as f:
        f.attrs["spacepol_fingerprint"] = print_


def check_resumable(path, posterior: Posterior, walkers: int | None, seed: int) -> None:
    """Before any work: a chain already in ``path`` must be readable and belong to this run."""
    _check_backend(Path(path), fingerprint(posterior, check_walkers(walkers, posterior.ndim), seed))


def check_walkers(walkers: int | None, ndim: int) -> int:
    """The number of walkers to use (the default when None); an impossible count is an error."""
    walkers = default_walkers(ndim) if walkers is None else walkers
    if walkers < 2 * ndim or walkers % 2:
        raise SpacepolError(f"--walkers {walkers}: need an even number >= 2 x {ndim} parameters = {2 * ndim}")
    return walkers


def invert(posterior: Posterior, seed: int = 0, walkers: int | None = None, max_steps: int = 20000,
           backend_path=None, progress: bool = True, check_every: int = 500, centre=None, space=None,
           tau_multiple: float = 50.0, max_pointwise_draws: int | None = None, elpd_tolerance: float | None = None) -> Result:
    """emcee posterior and its summary. ``centre``: a parameter vector (e.g. an optimum already found)
    around which the walkers start; by default a global optimisation finds one. ``space``: where the walkers
    move (``sampling_space``; default the logit of each prior's CDF). ``tau_multiple``: the chain is long
    enough at this many autocorrelation times (with R-hat <= 1.01 and ESS >= 400 besides).
    ``max_pointwise_draws``: PSIS-LOO and the posterior predictive from at most this many draws. ``elpd_tolerance``:
    for a caller that needs the ELPD-LOO alone (diagnose), the chain may stop before convergence where the ELPD-LOO
    of its two halves agree within this many log units (``elpd_settled``; ``summary.sampler["stopped_early"]``)."""
    start = time.perf_counter()
    rng = np.random.default_rng(seed)
    walkers = check_walkers(walkers, posterior.ndim)
    if backend_path is not None:
        backend_path = Path(backend_path)
        print_ = fingerprint(posterior, walkers, seed, (space or SamplingSpace).family)
        _check_backend(backend_path, print_)
        _stamp_backend(backend_path, print_)  # before sampling, so an interrupted chain is recognised
    result = sample_emcee(posterior, rng, walkers=walkers, max_steps=max_steps, backend_path=backend_path,
                          progress=progress, model_name=posterior.likelihood.model.name, seed=seed,
                          check_every=check_every, space=space, tau_multiple=tau_multiple,
                          initial=None if centre is None else ball(posterior, np.asarray(centre, float), walkers, rng),
                          enough=None if elpd_tolerance is None else settled(posterior, elpd_tolerance))
    if backend_path is not None:
        compact(backend_path)
    idata = to_inference_data(result, posterior, rng, max_pointwise_draws)
    loo_result = loo(idata)
    return summarised(posterior, result, idata, loo_result, {**convergence(idata, result), "engine": "emcee"}, seed, start)


class Emcee(Engine):
    """emcee's affine-invariant ensemble in the logit space of the priors, run until R-hat <= 1.01, ESS >= 400 and
    50 autocorrelation times (or ``max_steps``); its chain is kept in the output folder, so an interrupted run
    continues."""

    name, kind, resumable, default = "emcee", SAMPLER, True, True
    description = "affine-invariant ensemble sampler (emcee), resumable; the default"

    def run(self, posterior, rng, walkers: int | None = None, max_steps: int = 20000, tau_multiple: float = 50.0,
            progress: bool = False):
        """emcee's draws (``engines.emcee_sampler.sample_emcee``)."""
        return sample_emcee(posterior, rng, walkers=walkers, max_steps=max_steps, tau_multiple=tau_multiple,
                            progress=progress, model_name=posterior.likelihood.model.name)

    def result(self, posterior, seed: int = 0, progress: bool = False, chain=None, **options):
        """``inversion.invert``: the start-point search, the chain (kept in ``chain`` when given), the Result."""
        self.check_options(options)
        return invert(posterior, seed=seed, backend_path=chain, progress=progress, **options)

    def check_chain(self, chain, posterior, seed: int, walkers: int | None = None, **_) -> None:
        """A chain already in ``chain`` must be readable and belong to this run (before any work)."""
        check_resumable(chain, posterior, walkers, seed)
