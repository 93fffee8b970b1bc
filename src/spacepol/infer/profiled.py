"""The posterior with its inferred noise levels profiled out: the landscape the start-point searches climb.

With Gaussian noise, each inferred level's conditional maximum is closed-form: the RMS of its channels' scaled
residuals (``Likelihood.profiled``). A global search over the model's parameters alone then compares every
candidate at the noise it deserves. Searched with the levels as free coordinates, a random point pairs a good
model with a wrong noise level as often as a bad one with the right level, and on NIST's PTFE (four
wavelengths, ``paper+polarized_diffuse``) 7 of 9 searches ended on the plateau where the specular term is off
and every Mueller element's noise is the RMS of the data, or in a mode ~5,000 log units below the best.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import numpy as np

from .posterior import Posterior


class ProfiledPosterior(Posterior):
    """A posterior over the model's parameters (and any noise level not profiled), each set's noise ``levels``
    (((name, lower, upper), ...)) at their conditional maximum inside their priors' bounds."""

    def __init__(self, likelihood, priors, levels: tuple, full: Posterior):
        super().__init__(likelihood, priors, prior_only=False)
        self.levels, self.full = tuple(levels), full

    @classmethod
    def of(cls, posterior: Posterior) -> "ProfiledPosterior | None":
        """The profiled form of ``posterior``, or None when no free noise level can be profiled (errors in the
        file, fixed levels, a Student-t likelihood, a prior-only posterior)."""
        if posterior.prior_only:
            return None
        priors = posterior.priors
        names = [n for n in posterior.likelihood.profilable if n in priors.names]
        if not names or len(names) == priors.ndim:
            return None
        kept = [p for p in priors.parameters if p.name not in names]
        sub = type(priors)(kept, {p.name: priors.priors[p.name] for p in kept}, where="profiled noise")
        return cls(posterior.likelihood, sub, tuple((n, *map(float, priors.priors[n].bounds)) for n in names), posterior)

    def summed_log_likelihood(self, theta) -> np.ndarray:
        """The log-likelihood of each row of theta (W, D) at its profiled noise levels."""
        return self.likelihood.profiled(self.priors.to_params(theta), self.levels)[0]

    def complete(self, theta) -> np.ndarray:
        """The full posterior's parameter vectors (rows in ``full.priors.names`` order) for rows of theta: the
        kept parameters as they are, each profiled level at its conditional maximum."""
        theta = np.atleast_2d(theta)
        params = self.priors.to_params(theta)
        _, levels = self.likelihood.profiled(params, self.levels)
        values = {**{n: theta[:, j] for j, n in enumerate(self.priors.names)}, **levels}
        return np.column_stack([np.broadcast_to(values[n], len(theta)) for n in self.full.priors.names])
