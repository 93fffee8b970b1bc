"""Simulation-based calibration (SBC; Talts et al. 2018, arXiv:1804.06788) of any sampling engine.

Draw a truth from the prior, simulate data from it with Gaussian noise of known size, sample the posterior with the
engine, and record where the truth falls among the draws. If the engine samples the posterior the data imply, the
truth is one more draw from it: its rank among L independent draws is uniform on 0..L, and a central interval of
probability p holds it in a fraction p of the replicates. A sampler that is too narrow piles the ranks at both ends
(a U), one that is too wide piles them in the middle, a biased one tilts them.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

import jax
import numpy as np
from scipy import stats

from ..io.dataset import Dataset
from ..physics.geometry import Geometry
from .engine_registry import engines
from .engines.base import SAMPLER, Engine
from .posterior import Posterior
from .prior_set import PriorSet

RANK_DRAWS = 99  # L: ranks 0..99, ten bins of ten ranks
LEVELS = (0.5, 0.9)


@dataclass(frozen=True)
class Calibration:
    """SBC of one engine on one problem: per replicate and parameter the truth's rank among ``rank_draws`` thinned
    draws and whether the central 50 % and 90 % intervals hold it; ``refused``: replicates where the engine gave no
    draws (a Laplace approximation that failed its checks), left out of the ranks and said in ``to_json``."""

    engine: str
    names: tuple[str, ...]
    truths: np.ndarray  # (replicates, parameters)
    ranks: np.ndarray  # (replicates, parameters), 0..rank_draws
    inside: dict = field(default_factory=dict)  # level -> bool (replicates, parameters)
    rank_draws: int = RANK_DRAWS
    refused: int = 0
    seconds: float = 0.0
    likelihood_noise_scale: float = 1.0

    @property
    def replicates(self) -> int:
        """Replicates with draws."""
        return len(self.ranks)

    def coverage(self, level: float) -> np.ndarray:
        """Per parameter, the fraction of replicates whose central ``level`` interval holds the truth."""
        return self.inside[level].mean(axis=0)

    def coverage_band(self, level: float, z: float = 3.3) -> tuple[float, float]:
        """The binomial band (``z`` standard errors) a calibrated engine's coverage of one parameter lies in."""
        sd = np.sqrt(level * (1 - level) / self.replicates)
        return max(0.0, level - z * sd), min(1.0, level + z * sd)

    def rank_histogram(self, bins: int = 10) -> np.ndarray:
        """Counts per bin of the truth's rank (bins x parameters)."""
        edges = np.linspace(-0.5, self.rank_draws + 0.5, bins + 1)
        return np.stack([np.histogram(self.ranks[:, j], edges)[0] for j in range(len(self.names))], axis=1)

    def rank_p_values(self, bins: int = 10) -> np.ndarray:
        """Per parameter, the chi-square p-value of the rank histogram against uniform."""
        counts = self.rank_histogram(bins)
        return np.array([stats.chisquare(counts[:, j]).pvalue for j in range(counts.shape[1])])

    def failures(self, z: float = 3.3, alpha: float = 1e-3) -> list[str]:
        """What fails: a coverage outside its binomial band, or a rank histogram non-uniform at ``alpha`` (Bonferroni
        over the parameters); empty when the engine is calibrated here."""
        out = []
        for level in LEVELS:
            lo, hi = self.coverage_band(level, z)
            for name, c in zip(self.names, self.coverage(level)):
                if not lo <= c <= hi:
                    out.append(f"{name}: {level:.0%} intervals hold the truth in {c:.1%} of {self.replicates} replicates "
                               f"(a calibrated engine: {lo:.1%}-{hi:.1%})")
        for name, p in zip(self.names, self.rank_p_values()):
            if p < alpha / len(self.names):
                out.append(f"{name}: ranks not uniform (chi-square p = {p:.1e})")
        return out

    @property
    def calibrated(self) -> bool:
        """Every coverage in its band and every rank histogram uniform."""
        return not self.failures()

    def to_json(self) -> dict:
        """The figures per parameter, the verdict and what failed."""
        failures = self.failures()
        c50, c90, p, counts = self.coverage(0.5), self.coverage(0.9), self.rank_p_values(), self.rank_histogram()
        return {"engine": self.engine, "replicates": self.replicates, "refused": self.refused,
                "rank_draws": self.rank_draws, "likelihood_noise_scale": self.likelihood_noise_scale,
                "seconds": self.seconds, "calibrated": not failures, "failures": failures,
                "parameters": {name: {"coverage_50": float(c50[j]), "coverage_90": float(c90[j]),
                                      "rank_p_value": float(p[j]), "rank_histogram": counts[:, j].tolist()}
                               for j, name in enumerate(self.names)}}

    def figure(self, bins: int = 10):
        """Rank histograms, one panel per parameter, with the band (99 %) a uniform histogram's bins lie in."""
        from matplotlib.figure import Figure

        counts = self.rank_histogram(bins)
        expected = self.replicates / bins
        lo, hi = stats.binom.ppf([0.005, 0.995], self.replicates, 1 / bins)
        fig = Figure(figsize=(3.2 * len(self.names), 2.8), layout="constrained")
        axes = fig.subplots(1, len(self.names), squeeze=False)[0]
        for ax, name, column, c90 in zip(axes, self.names, counts.T, self.coverage(0.9)):
            ax.axhspan(lo, hi, color="0.85", label="99 % band of a uniform histogram")
            ax.axhline(expected, color="0.5", lw=0.8)
            ax.bar(np.arange(bins), column, width=0.9, color="C0")
            ax.set_title(f"{name}: 90 % intervals hold {c90:.0%}", fontsize=9)
            ax.set_xlabel(f"rank of the truth (bin of {(self.rank_draws + 1) // bins})")
            ax.set_xticks([])
        axes[0].set_ylabel(f"replicates (of {self.replicates})")
        axes[0].legend(fontsize=7, loc="lower center")
        fig.suptitle(f"SBC of {self.engine}" + (f", likelihood noise x{self.likelihood_noise_scale:.3g}"
                                                if self.likelihood_noise_scale != 1 else ""), fontsize=10)
        return fig


def simulate(model, truth: dict, geometry: Geometry, rng: np.random.Generator, noise_dop: float = 0.01,
             noise_brdf: float = 0.05, mueller_noise: float | None = None) -> Dataset:
    """Data from ``model`` at ``truth`` with Gaussian noise of known size and nothing clipped: DOP (absolute
    ``noise_dop``) and BRDF (relative ``noise_brdf``), or with ``mueller_noise`` the 15 normalised Mueller elements
    (absolute) and the BRDF."""
    prediction = model.evaluate(truth, geometry, mueller=mueller_noise is not None)
    n = geometry.size
    data = Dataset(geometry.theta_i, geometry.theta_r, geometry.dphi, geometry.wavelength_um,
                   source=f"SBC replicate of {model.name}")
    data.brdf = prediction.brdf * (1.0 + noise_brdf * rng.standard_normal(n))
    data.brdf_err = noise_brdf * prediction.brdf
    if mueller_noise is None:
        data.dop = prediction.dop + noise_dop * rng.standard_normal(n)
        data.dop_err = np.full(n, noise_dop)
    else:
        m = np.asarray(prediction.mueller, float)
        normalised = m / m[0, 0]
        noisy = normalised + mueller_noise * rng.standard_normal(normalised.shape)
        noisy[0, 0] = 1.0
        data.mueller = noisy * data.brdf
        data.mueller_err = np.full(normalised.shape, mueller_noise)
    return data


def _thinned(samples: np.ndarray, count: int) -> np.ndarray:
    """``count`` draws evenly spaced through the run (draws x chains x D), chains taken in turn: as nearly
    independent as the run allows without knowing its autocorrelation."""
    draws, chains, ndim = samples.shape
    flat = samples.reshape(draws * chains, ndim)  # draw-major: draw 0 of every chain, then draw 1, ...
    index = np.linspace(0, len(flat) - 1, count).round().astype(int)
    return flat[index]


def calibrate(engine: str, model, priors: dict, geometry: Geometry, replicates: int, rng: np.random.Generator, *,
              engine_options: dict | None = None, noise_dop: float = 0.01, noise_brdf: float = 0.05,
              mueller_noise: float | None = None, likelihood_noise_scale: float = 1.0, rank_draws: int = RANK_DRAWS,
              progress: bool = False) -> Calibration:
    """SBC of the sampling ``engine`` (a registry name, or an ``Engine`` instance) for ``model`` with ``priors``
    (name -> Prior; the model's defaults otherwise) at ``geometry``: ``replicates`` truths drawn from the prior, one data set each, one run each
    with ``engine_options``. ``rng`` draws the truths, the noise and each run's seed."""
    from ..errors import SpacepolError

    sampler = engine if isinstance(engine, Engine) else engines.get(engine, kind=SAMPLER)
    options = dict(engine_options or {})
    sampler.check_options(options)
    prior_set = PriorSet(model.parameters, priors)
    names = tuple(prior_set.names)
    start = time.perf_counter()
    truths, ranks, inside, refused = [], [], {level: [] for level in LEVELS}, 0
    for r in range(replicates):
        theta = prior_set.sample(rng, 1)[0]
        truth = {**prior_set.fixed, **dict(zip(names, map(float, theta)))}
        data = simulate(model, truth, geometry, rng, noise_dop, noise_brdf, mueller_noise)
        if likelihood_noise_scale != 1.0:
            for attribute in ("dop_err", "brdf_err", "mueller_err"):
                if getattr(data, attribute) is not None:
                    setattr(data, attribute, getattr(data, attribute) * likelihood_noise_scale)
        posterior = Posterior.build(data, model, priors)
        if tuple(posterior.names) != names:  # e.g. noise levels inferred: the truth would not cover them
            raise SpacepolError(f"SBC: the posterior samples {list(posterior.names)}, the prior draws {list(names)}")
        try:
            samples = np.asarray(sampler.run(posterior, np.random.default_rng(int(rng.integers(2**31))), **options).samples)
        except SpacepolError:
            refused += 1
            continue
        flat = samples.reshape(-1, samples.shape[-1])
        truths.append(theta)
        ranks.append((_thinned(samples, rank_draws) < theta).sum(axis=0))
        for level in LEVELS:
            lo, hi = np.quantile(flat, [(1 - level) / 2, (1 + level) / 2], axis=0)
            inside[level].append((lo <= theta) & (theta <= hi))
        # every replicate's data are compiled into its own programs: drop JAX's caches of them, or a long calibration
        # runs out of memory mappings (the NUTS benchmark died at LLVM "Cannot allocate memory" within 100 replicates)
        del posterior
        jax.clear_caches()
        if progress:
            print(f"  SBC {sampler.label} {r + 1}/{replicates} ({time.perf_counter() - start:.0f} s)", file=sys.stderr, flush=True)
    return Calibration(engine=sampler.label, names=names, truths=np.array(truths), ranks=np.array(ranks),
                       inside={level: np.array(v) for level, v in inside.items()}, rank_draws=rank_draws,
                       refused=refused, seconds=time.perf_counter() - start,
                       likelihood_noise_scale=likelihood_noise_scale)
