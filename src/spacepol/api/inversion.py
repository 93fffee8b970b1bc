"""Posteriors and engines from Python: ``invert`` (any registered sampler, its report and resumable chain in
``out``), ``calibrate`` (simulation-based calibration of an engine), ``optimize`` (one engine's best fit) and
``compare`` (several engines on one posterior)."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..infer.result import Result
from ..io.dataset import Dataset
from .inputs import as_dataset, build_model, build_posterior, parse_observables


def invert(data, model="paper", prior=None, engine: str = "emcee", seed: int = 0, out=None, *,
           observables=None, dispersion=None, walkers: int | None = None, steps: int | None = None,
           robust: bool = False, restart: bool = False, progress: bool = False, references: dict | None = None,
           engine_options: dict | None = None) -> Result:
    """Sample the posterior of ``model`` (an effect list, a preset or a Model) on ``data`` (a Dataset or a file path) and return its Result.

    ``engine``: a sampler of the engine registry: ``emcee`` (affine-invariant ensemble, the default), ``laplace`` (a
    Laplace approximation at the optimum corrected by importance sampling; emcee where its checks refuse it, and the
    summary says so: ``engine`` and ``laplace_refused``), ``nuts``, an entry point of group ``spacepol.engines`` or a
    file ``path/to/engine.py:Name``.
    ``walkers`` and ``steps`` are emcee's (``walkers``, ``max_steps``); ``engine_options`` go to the engine's ``run``.
    With ``out`` the run is kept in that folder as ``invert-mcmc run`` keeps it: for a resumable engine (emcee) the
    chain (an interrupted call continues with the same arguments; ``restart`` starts afresh and keeps the old chain
    aside), posterior.nc, summary.json, figures and report.html. ``references``: {parameter: value} to compare the
    posterior with (e.g. a known index)."""
    from ..infer.engine_registry import SAMPLER, engines

    sampler = engines.get(engine, SAMPLER)
    options = {**({"walkers": walkers} if walkers is not None else {}),
               **({"max_steps": steps} if steps is not None else {}), **(engine_options or {})}
    sampler.check_options(options)
    parse_observables(observables)  # registers a user's observable file before its columns are read
    data = as_dataset(data)
    post = build_posterior(data, model, prior, observables, dispersion, robust)
    if walkers is not None:
        from ..infer.inversion import check_walkers

        check_walkers(walkers, post.ndim)
    if references:
        for name, value in references.items():
            if name not in post.names:
                raise ParameterError(f"--reference '{name}={value:g}': '{name}' is not a free parameter "
                                     f"({', '.join(post.names)})")
    if out is None:
        return sampler.result(post, seed=seed, progress=progress, **options)
    return _invert_into(Path(out), post, sampler, seed, options, restart, progress, references)


def _invert_into(out: Path, post, sampler, seed, options, restart, progress, references) -> Result:
    from ..infer.chain_file import set_aside
    from ..io.output import check_output_dir, folder_lock
    from ..report.run_report import write_run_report

    check_output_dir(out)
    made_folder = not out.exists()
    chain = out / "chain.h5" if sampler.resumable else None
    fresh = chain is None or not chain.exists()
    with folder_lock(out):  # first: a second run on this folder stops here, before it reads the chain
        try:
            if chain is not None and not restart:
                sampler.check_chain(chain, post, seed, **options)
            if progress:
                lik = post.likelihood
                print(f"sampling {', '.join(post.names)} from {len(lik.data)} geometries ({', '.join(lik.observables)}), "
                      f"model {lik.model.name}", file=sys.stderr)
                if lik.left_out:
                    print(f"  not fitted: {', '.join(lik.left_out)} ({' and '.join(sorted(set(lik.left_out.values())))} "
                          f"holds their numbers; --observables chooses)", file=sys.stderr)
            if restart and chain is not None and (old := set_aside(chain)) is not None and progress:
                print(f"  --restart: the previous chain is kept as {old}", file=sys.stderr)
            result = sampler.result(post, seed=seed, progress=progress, chain=chain, **options)
        except KeyboardInterrupt:
            raise  # the chain so far is kept: the same call continues it
        except BaseException:
            _discard_unstarted(chain, out, fresh or restart, made_folder)
            raise
        if progress:
            print("  writing the report (figures, posterior.nc, summary.json, report.html)", file=sys.stderr)
        write_run_report(result, out, data_label(post.likelihood.data), references=references)
    return result


def data_label(data: Dataset) -> str:
    """How reports name the data: the file they came from, else "data"."""
    return data.source or "data"


def _discard_unstarted(chain: Path | None, out: Path, fresh: bool, made_folder: bool) -> None:
    """A run that failed before its first stored step leaves nothing behind that would block the
    corrected call (a chain stamped with the failed run's settings would)."""
    from ..infer.chain_file import ChainFileError, chain_iterations

    if chain is not None:
        try:
            empty = fresh and chain.exists() and chain_iterations(chain) == 0
        except ChainFileError:
            empty = fresh
        if empty:
            chain.unlink(missing_ok=True)
    if made_folder and out.is_dir() and not any(p.name != ".spacepol.lock" for p in out.iterdir()):
        import shutil

        shutil.rmtree(out, ignore_errors=True)


def calibrate(model, priors: dict, geometry, *, engine="emcee", replicates: int = 100, seed: int = 0,
              engine_options: dict | None = None, noise_dop: float = 0.01, noise_brdf: float = 0.05,
              mueller_noise: float | None = None, likelihood_noise_scale: float = 1.0, progress: bool = False):
    """Simulation-based calibration of a sampling ``engine`` (a registry name or an ``Engine``;
    ``infer.calibration``): ``replicates`` truths from ``priors`` ({name: Prior}; the model's defaults for the rest),
    data simulated at ``geometry`` (a Geometry, a Dataset or a file of geometries) with Gaussian noise of known size,
    one run each. Returns a ``Calibration``:
    coverage of the 50 % and 90 % intervals, rank histograms and their figure, ``calibrated``, ``failures``."""
    from ..infer.calibration import calibrate as run_sbc
    from ..io.measurements import read_measurements

    if replicates < 1:
        raise ParameterError(f"replicates {replicates}: need at least 1")
    if isinstance(geometry, (str, Path)):
        geometry = read_measurements(geometry, require_observable=False)
    geometry = geometry.geometry if isinstance(geometry, Dataset) else geometry
    return run_sbc(engine, build_model(model), priors, geometry, replicates, np.random.default_rng(seed),
                   engine_options=engine_options, noise_dop=noise_dop, noise_brdf=noise_brdf,
                   mueller_noise=mueller_noise, likelihood_noise_scale=likelihood_noise_scale, progress=progress)


def optimize(data, model="paper", method: str = "ga", prior=None, *, observables=None, dispersion=None,
             seed: int = 0):
    """One engine's best fit on ``data`` (an EngineResult; ``to_json()`` is what ``invert-mcmc optimize`` prints):
    an optimizer (``ga``, ``de``, ``nlopt:ALGO``) on the paper's objective over ``model``'s own parameters, or a
    sampler (``emcee``, ...) on the posterior."""
    from ..infer.engine_registry import SAMPLER, check_method, engines
    from ..infer.engine_registry import optimize as run_optimizer
    from ..infer.objective import PaperObjective
    from ..infer.prior_set import PriorSet

    check_method(method)
    data = as_dataset(data)
    posterior = build_posterior(data, model, prior, observables, dispersion)
    engine = engines.get(method)
    if engine.kind == SAMPLER:
        return engine.result(posterior, seed=seed).draws
    fitted = posterior.likelihood.model
    own = {p.name for p in fitted.parameters}
    model_priors = PriorSet(fitted.parameters, {n: pr for n, pr in posterior.priors.priors.items() if n in own})
    return run_optimizer(method, PaperObjective(data, fitted, model_priors), np.random.default_rng(seed), fitted.name,
                         seed=seed)


@dataclass
class Comparison:
    """Several engines on one posterior: ``content`` (optimizers.json: per engine and seed the best objective, the
    evaluations it took and the spread of the optima) and the folder its figures and report went to (``out``)."""

    content: dict
    out: Path

    def to_json(self) -> dict:
        """``optimizers.json``'s content."""
        return self.content


def compare(data, model="paper", methods=None, seeds: int = 3, out="reports/compare", prior=None, *,
            observables=None, dispersion=None, seed: int = 0) -> Comparison:
    """Several engines (``methods``; default every optimizer and the samplers), ``seeds`` seeds each, on the same
    posterior against its reference; figures, table and report.html in ``out``."""
    from ..infer.engine_registry import check_method
    from ..io.output import check_output_dir
    from ..report.compare import run_comparison

    out = check_output_dir(Path(out))
    for method in methods or []:
        check_method(method)
    data = as_dataset(data)
    posterior = build_posterior(data, model, prior, observables, dispersion)
    return Comparison(run_comparison(posterior, data, out, methods=methods, seeds=seeds, base_seed=seed), out)
