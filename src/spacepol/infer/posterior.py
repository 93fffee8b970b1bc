"""Posterior = likelihood x priors, vectorised over walkers (parameter sets)."""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..physics.plugin_guard import is_plugin
from .likelihood import Likelihood
from .measured_noise import measure
from .prior_set import PriorSet


class Posterior:
    """The log posterior over the free parameters ``names``: a ``Likelihood`` and the ``PriorSet`` of the model's
    parameters and its noise levels. Callable on rows of parameter vectors (W, D) -> (W,); ``build`` assembles it
    from a data set and a model, with the noise the data measure themselves as a floor of the inferred noise."""

    def __init__(self, likelihood: Likelihood, priors: PriorSet, prior_only: bool = False):
        self.likelihood, self.priors = likelihood, priors
        self.prior_only = prior_only  # sample the prior alone (a check of the sampler and the priors)
        self.names = priors.names
        self.n_evaluations = 0
        if likelihood.n_obs < priors.ndim:
            raise ParameterError(
                f"{likelihood.data.source}: {likelihood.n_obs} observations are fewer than the "
                f"{priors.ndim} free parameters ({', '.join(priors.names)})"
            )

    measured_noise: dict = {}  # {noise parameter: MeasuredNoise} the data measure themselves (set by build)

    @classmethod
    def build(cls, data, model, prior_overrides=None, observables=None, robust=False, where="priors",
              noise_floor: bool = True, check: bool = True):
        """Likelihood and priors of ``model`` on ``data``. Where the data measure their own noise (reciprocal
        pairs, repeated geometries: ``measured_noise``), an inferred noise level's prior starts at the measured
        level's floor, so that no fit claims less noise than the measurement shows (``noise_floor=False``
        keeps the default priors; a prior file's own prior for the level always wins). ``check``: run
        ``check_support`` now (it compiles the likelihood); without it, ``ensure_checked`` runs it before first use
        (a process that only reads the priors, while another process evaluates the posterior, compiles nothing)."""
        likelihood = Likelihood(data, model, observables=observables, robust=robust)
        measured = measure(likelihood)
        nuisance = [_floored(p, measured[p.name]) if noise_floor and p.name in measured and p.name not in (prior_overrides or {})
                    else p for p in likelihood.nuisance]
        priors = PriorSet(model.parameters + nuisance, prior_overrides, where=where)
        posterior = cls(likelihood, priors)
        posterior.measured_noise = measured
        posterior._where = where
        if check:
            posterior.check_support(where)
        return posterior

    _checked = False
    _where = "priors"

    def on_rows(self, rows) -> "Posterior":
        """The same model, observables and priors (noise floors included) on a subset of the data's rows (indices or
        a boolean mask): e.g. a cheaper posterior for a global search whose optimum is then polished on every row."""
        likelihood = self.likelihood
        subset = Likelihood(likelihood.data.select(rows), likelihood.model, observables=likelihood.observable_names,
                            robust=likelihood.robust, nu=likelihood.nu)
        posterior = type(self)(subset, self.priors)
        posterior.measured_noise, posterior._where = getattr(self, "measured_noise", {}), self._where
        return posterior

    def ensure_checked(self) -> "Posterior":
        """``check_support`` once (a posterior built with ``check=False``); returns the posterior."""
        if not self._checked:
            self.check_support(self._where)
        return self

    def check_support(self, where: str = "priors", draws: int = 255) -> None:
        """Before any sampling: plug-in effects give finite predictions, and the posterior is finite
        somewhere in the prior support (else one line says which part is at fault).  Uses its own
        fixed-seed generator, so the user's random stream is untouched."""
        rng = np.random.default_rng(20261122)
        theta = np.vstack([self.priors.rescale(np.full((1, self.ndim), 0.5)), self.priors.sample(rng, draws)])
        model = self.likelihood.model
        if any(is_plugin(e) for e in model.effects):  # built-in effects need no guard (and a compilation of their own)
            model.check_plugins(self.model_params(theta), self.likelihood.data.geometry)
        lp = self.priors.ln_prob(theta)
        if not np.any(np.isfinite(lp)):
            raise ParameterError(f"{where}: the prior density is zero at every one of {len(theta)} draws from it")
        if not self.prior_only:
            ll = self.likelihood.total(self.priors.to_params(theta))
            if not np.any(np.isfinite(ll)):
                raise ParameterError(
                    f"{self.likelihood.data.source}: the likelihood is not finite at any of {len(theta)} draws from the "
                    f"priors ({where}); the model cannot produce these data anywhere the priors allow")
        self._checked = True

    @property
    def ndim(self) -> int:
        """The number of free parameters."""
        return self.priors.ndim

    def model_params(self, theta) -> dict:
        """{model parameter: values} for the rows of theta (W, D); the likelihood's noise levels left out."""
        names = {p.name for p in self.likelihood.model.parameters}
        return {k: v for k, v in self.priors.to_params(np.atleast_2d(theta)).items() if k in names}

    def log_prob_pointwise(self, theta) -> np.ndarray:
        """The log likelihood of each fitted number for each row of theta (W, D) -> (W, numbers): what PSIS-LOO reads."""
        theta = np.atleast_2d(theta)
        return self.likelihood.pointwise(self.priors.to_params(theta))

    def log_prob(self, theta) -> np.ndarray:
        """log posterior (up to a constant) for each row of theta (W, D); -inf outside the priors."""
        theta = np.atleast_2d(theta)
        lp = self.priors.ln_prob(theta)
        return lp + self.log_likelihood(theta, np.isfinite(lp))

    def log_likelihood(self, theta, inside=None) -> np.ndarray:
        """log-likelihood for each row of theta (W, D) (0 for a prior-only posterior); -inf where it is not
        finite and in the rows not ``inside`` (a boolean mask; default every row)."""
        theta = np.atleast_2d(theta)
        inside = np.ones(len(theta), bool) if inside is None else inside
        if self.prior_only:
            return np.where(inside, 0.0, -np.inf)
        out = np.full(len(theta), -np.inf)
        if np.any(inside):
            # every row is evaluated (those outside the priors are discarded after): a fixed batch size is
            # one compiled program, where the varying count of rows inside would compile one per size
            ll = self.summed_log_likelihood(theta)[inside]
            self.n_evaluations += int(inside.sum())
            out[inside] = np.where(np.isfinite(ll), ll, -np.inf)
        return out

    def summed_log_likelihood(self, theta) -> np.ndarray:
        """The likelihood's sum per row of theta (W, D), every row evaluated (``log_likelihood`` masks)."""
        theta = np.atleast_2d(theta)
        if theta.shape[1] != self.priors.ndim:
            return self.likelihood.total(self.priors.to_params(theta))
        # theta's columns are the free parameters in order: the compiled call's matrix as it is (a sampler's step)
        held = tuple(sorted((n, float(v)) for n, v in self.priors.fixed.items()))
        return self.likelihood.of_matrix(1, tuple(self.priors.names), held, np.asarray(theta, float))

    def __call__(self, theta):
        return self.log_prob(theta)


class PinnedPosterior(Posterior):
    """``parent`` with some of its free parameters held at values (an effect's branch, e.g. a dielectric's k = 0),
    over the others (``priors``: the parent's with those parameters fixed). Evaluated through the parent's compiled
    program with the held values as columns: held as constants they would compile a program of their own (seconds
    for a full-Mueller model, paid by every screened candidate)."""

    def __init__(self, parent: Posterior, priors: PriorSet, pinned: dict):
        super().__init__(parent.likelihood, priors, prior_only=parent.prior_only)
        self.parent, self.pinned = parent, dict(pinned)
        names = list(parent.priors.names)
        if sorted(priors.names + list(self.pinned)) != sorted(names):
            raise ValueError(f"a branch must pin free parameters of the posterior ({', '.join(names)}): {self.pinned}")
        self._free = [names.index(n) for n in priors.names]
        self._held = [(names.index(n), float(v)) for n, v in self.pinned.items()]

    def expand(self, theta) -> np.ndarray:
        """The parent's parameter vectors for rows of theta (W, D): the held values put back."""
        theta = np.atleast_2d(theta)
        out = np.empty((len(theta), self.parent.ndim))
        out[:, self._free] = theta
        for j, value in self._held:
            out[:, j] = value
        return out

    def summed_log_likelihood(self, theta) -> np.ndarray:
        return self.parent.summed_log_likelihood(self.expand(theta))


def _floored(parameter, measured):
    """``parameter`` (a noise level) with its prior's lower bound raised to the measured level's floor."""
    import dataclasses

    prior = parameter.prior
    lower = min(max(prior.lower, measured.floor), 0.5 * prior.upper)
    return dataclasses.replace(parameter, prior=type(prior)(lower, prior.upper),
                               description=f"{parameter.description}; at least {lower:.3g}, the floor of the noise "
                                           f"the data measure themselves ({measured.source})")
