"""Engines: each takes an objective or a posterior, a prior cube and a Generator, and returns an EngineResult.

``optimize(method, ...)`` dispatches the method names of DESIGN.md: ``ga``, ``de``,
``nlopt:ALGO`` (and ``emcee`` through :mod:`.emcee_sampler`).
"""

from ...errors import UnknownNameError
from .de import run_de
from .ga import run_ga
from .nlopt_engine import NLOPT_ALGORITHMS, check_algorithm, run_nlopt

OPTIMIZERS = ["ga", "de"] + [f"nlopt:{a}" for a in NLOPT_ALGORITHMS]


def check_method(method: str) -> str:
    """A method name of DESIGN.md (``ga``, ``de``, ``emcee``, ``nlopt:ALGO``), checked before any work."""
    if method in ("ga", "de", "emcee"):
        return method
    if method.startswith("nlopt:"):
        check_algorithm(method.split(":", 1)[1])
        return method
    raise UnknownNameError(f"unknown method '{method}' (known: ga, de, emcee, nlopt:ALGO with ALGO in {', '.join(NLOPT_ALGORITHMS)})")


def optimize(method: str, objective, rng, model_name: str = "", **options):
    """Run the optimizer ``method`` (``ga``, ``de``, ``nlopt:ALGO``) on ``objective``; its EngineResult."""
    if method == "ga":
        return run_ga(objective, rng, model_name=model_name, **options)
    if method == "de":
        return run_de(objective, rng, model_name=model_name, **options)
    if method.startswith("nlopt:"):
        return run_nlopt(objective, method.split(":", 1)[1], rng, model_name=model_name, **options)
    raise UnknownNameError(f"unknown method '{method}' (known: ga, de, emcee, nlopt:ALGO with ALGO in {', '.join(NLOPT_ALGORITHMS)})")
