"""A full Bayesian inversion in one call: ``invert`` (emcee, resumable) and ``laplace_fit`` (Laplace-IS), the two
engines the library's own commands run (``engines.emcee_engine``, ``engines.laplace_is``), gathered for callers."""

from __future__ import annotations

from .engines.emcee_engine import check_resumable, check_walkers, fingerprint, invert
from .engines.laplace_is import NO_LAPLACE, invert_laplace, laplace_fit

__all__ = ["NO_LAPLACE", "check_resumable", "check_walkers", "fingerprint", "invert", "invert_laplace", "laplace_fit"]
