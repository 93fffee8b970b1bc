"""One inversion's whole outcome, whatever engine made it: the ArviZ groups, the typed diagnostics, the engine
and its settings, the seed and the full model spec; ``save(dir)`` and ``Result.load(dir)`` round-trip it.

A Result made by an engine also holds the :class:`~spacepol.infer.posterior.Posterior` it sampled (data, model,
priors: what the figures and criticism need). A loaded Result has no Posterior: its data are in the
``observed_data`` group and its model is rebuilt from the stored spec (``Result.model``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SpacepolError
from .engine_result import EngineResult
from .engine_result import ESS_TARGET, RHAT_TARGET
from .run_summary import RunSummary

SUMMARY_FILE = "summary.json"
POSTERIOR_FILE = "posterior.nc"


@dataclass(frozen=True)
class Diagnostics:
    """How the draws were obtained and whether they can be trusted. MCMC: converged when R-hat <= 1.01 and ESS >= 400
    for every parameter (``capped``: the chain stopped at its step cap before 50 autocorrelation times). Laplace-IS: importance weights that passed their Pareto-k and width checks
    (``pareto_k``; ``ess_min`` is then the effective number of draws)."""

    engine: str
    converged: bool
    rhat_max: float | None
    ess_min: float | None
    tau_max: float | None
    steps: int | None
    pareto_k: float | None
    capped: bool

    def to_json(self) -> dict:
        """The fields as a JSON-ready dict."""
        return dict(self.__dict__)


@dataclass(frozen=True)
class Fit:
    """How well the posterior-median model matches the data: reduced chi^2, RMSE of DOP (None without measured
    DOP), ELPD-LOO and its standard error, and the misfit per noise group (inferred / measured noise, where the
    data measure their own noise)."""

    chi2_red: float
    rmse_dop: float | None
    elpd_loo: float
    elpd_loo_se: float
    misfit: dict[str, float]

    def to_json(self) -> dict:
        """The fields as a JSON-ready dict."""
        return dict(self.__dict__)


def _finite_or_none(value) -> float | None:
    return None if value is None or not np.isfinite(value) else float(value)


@dataclass
class Result:
    """One inversion: ``posterior`` (data, model, priors; None for a loaded Result), ``draws`` (the engine's
    draws and best point), ``idata`` (ArviZ groups posterior, sample_stats, log_likelihood, posterior_predictive,
    observed_data), ``summary`` (what summary.json holds), ``loo`` (the PSIS-LOO record) and
    ``identifiability``. Typed views: ``diagnostics``, ``fit``, ``spec``, ``engine``, ``seed``, ``log_evidence``;
    draws by name: ``samples()``."""

    posterior: object | None
    draws: EngineResult
    idata: object
    summary: RunSummary
    loo: dict
    identifiability: dict

    @property
    def engine(self) -> str:
        """The engine that made the draws (emcee, laplace-is, nuts, ...)."""
        return self.summary.engine_ran or self.draws.method

    @property
    def engine_settings(self) -> dict:
        """The engine's own settings and run figures (walkers, steps, burn-in, thinning, ...)."""
        return dict(self.summary.sampler)

    @property
    def seed(self) -> int:
        """The seed of the one Generator the run used."""
        return int(self.summary.seed)

    @property
    def spec(self) -> dict:
        """The whole model: effects, plug-in sources, wavelengths, dispersion (``physics.model_spec``), and the
        observables fitted (the channels; a user's observable with its source) and the priors used."""
        spec = self.summary.model_spec
        spec = {"effects": spec, "plugins": {}, "wavelengths_um": None, "dispersion": {}} if isinstance(spec, str) else spec
        return {**spec, "observables": list(self.summary.observables),
                "observable_plugins": dict(self.summary.observable_plugins),
                "priors": dict(self.summary.priors),
                "fixed": dict(self.summary.fixed)}

    @property
    def model(self):
        """The Model (one wavelength) or SpectralModel, rebuilt from the spec for a loaded Result."""
        if self.posterior is not None:
            return self.posterior.likelihood.model
        from ..physics.model_spec import model_from_spec

        return model_from_spec(self.summary.model_spec)

    @property
    def log_evidence(self) -> tuple[float, float] | None:
        """(ln Z, its standard error) when the engine estimates the evidence (a nested sampler), else None."""
        value = self.summary.log_evidence
        return None if value is None else (float(value["value"]), float(value["error"]))

    @property
    def diagnostics(self) -> Diagnostics:
        """Convergence or importance-weight diagnostics, typed."""
        d, sampler = self.summary.diagnostics, self.summary.sampler
        engine = d.get("engine") or "emcee"
        capped = bool(sampler.get("capped", False))
        if engine == "laplace-is":
            converged = True  # invert_laplace returns only weights that passed its checks
        else:
            rhat, ess = d.get("rhat_max"), d.get("ess_min")
            converged = rhat is not None and ess is not None and rhat <= RHAT_TARGET and ess >= ESS_TARGET
        steps = sampler.get("steps")
        return Diagnostics(engine=engine, converged=bool(converged), rhat_max=_finite_or_none(d.get("rhat_max")),
                           ess_min=_finite_or_none(d.get("ess_min")), tau_max=_finite_or_none(d.get("tau_max")),
                           steps=None if steps is None else int(steps), pareto_k=_finite_or_none(d.get("pareto_k")),
                           capped=capped)

    @property
    def fit(self) -> Fit:
        """Fit statistics, typed."""
        f = self.summary.fit
        return Fit(chi2_red=float(f["chi2_red"]), rmse_dop=f.get("rmse_dop"), elpd_loo=float(f["elpd_loo"]),
                   elpd_loo_se=float(f["elpd_loo_se"]),
                   misfit={k: float(v["ratio"]) for k, v in self.summary.noise.items()})

    def samples(self, include_fixed: bool = True) -> dict[str, np.ndarray]:
        """{parameter: flat draws} of every free parameter; fixed parameters as 0-d arrays when ``include_fixed``."""
        flat = self.draws.flat_samples()
        out = {name: flat[:, j] for j, name in enumerate(self.draws.names)}
        if include_fixed:
            for name, value in self.summary.fixed.items():
                out.setdefault(name, np.asarray(float(value)))
        return out

    def median(self) -> dict[str, float]:
        """The posterior median of every free parameter."""
        return {name: float(np.median(v)) for name, v in self.samples(include_fixed=False).items()}

    def to_json(self) -> dict:
        """summary.json's content (its fixed fields: model, spec, parameters, diagnostics, fit, seconds, seed,
        observables, priors, fixed, map, sampler, identifiability)."""
        return self.summary.to_json()

    def save(self, folder) -> Path:
        """Write ``posterior.nc`` (ArviZ groups, the pointwise ones thinned for storage) and ``summary.json`` into
        ``folder`` (made if missing); returns the folder."""
        from ..io.atomic import atomic_path, write_json
        from .inference_data import for_storage

        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        with atomic_path(folder / POSTERIOR_FILE) as tmp:
            for_storage(self.idata).to_netcdf(str(tmp))
        write_json(folder / SUMMARY_FILE, self.summary.to_json())
        return folder

    @classmethod
    def load(cls, folder) -> "Result":
        """The Result a ``save`` (or ``invert-mcmc run``) wrote into ``folder``; one clear error when it is not
        such a folder or its files are damaged."""
        import arviz as az

        folder = Path(folder)
        if not folder.is_dir():
            raise SpacepolError(f"{folder}: not a folder (give the --out folder of `invert-mcmc run` or Result.save)")
        summary_path, posterior_path = folder / SUMMARY_FILE, folder / POSTERIOR_FILE
        for path in (summary_path, posterior_path):
            if not path.is_file():
                raise SpacepolError(f"{path}: missing; is {folder} the output folder of `invert-mcmc run`?")
        try:
            content = json.loads(summary_path.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError):
            content = None
        summary = RunSummary.from_json(content, str(summary_path))
        try:
            idata = az.from_netcdf(str(posterior_path))
            post = idata.posterior
        except Exception as exc:  # netCDF/HDF5 raise many types for a damaged file
            raise SpacepolError(f"{posterior_path}: cannot read the posterior ({type(exc).__name__})") from None
        names = [n for n in post.data_vars]
        samples = np.stack([np.asarray(post[n]) for n in names], axis=-1).transpose(1, 0, 2)  # (draws, chains, D)
        log_prob = (np.asarray(idata.sample_stats["lp"]).T if "sample_stats" in idata.groups()
                    and "lp" in idata.sample_stats else None)
        attrs = post.attrs
        draws = EngineResult(method=str(attrs.get("method", summary.diagnostics.get("engine", "emcee"))),
                             model=summary.model, names=names, best=dict(summary.map),
                             objective=np.nan, objective_name="negative_log_posterior", n_evaluations=0,
                             seconds=float(summary.seconds), seed=int(summary.seed),
                             samples=samples, log_prob=log_prob, info=dict(summary.sampler))
        return cls(posterior=None, draws=draws, idata=idata, summary=summary,
                   loo={k: summary.fit[k] for k in ("elpd_loo", "elpd_loo_se")} if summary.fit else {},
                   identifiability=dict(summary.identifiability))
