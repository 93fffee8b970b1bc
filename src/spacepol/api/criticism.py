"""Model criticism from Python: ``diagnose`` (which effect is missing or wrong), ``ladder`` (the error falling
rung by rung) and ``design`` (which measurement would break a degeneracy)."""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError, UnknownNameError
from ..infer.result import Result
from ..physics.model import Model
from .inputs import as_dataset, build_model, build_posterior, parse_observables, prior_overrides
from .inversion import data_label


@dataclass
class Diagnosis:
    """What ``diagnose`` found: ``content`` is the JSON record (verdict, conclusion, ranking of every candidate
    change with delta ELPD-LOO and its standard error, how each refit's posterior was obtained; with rounds the
    path), ``base`` the Result of the starting model, ``confirmed`` the refitted candidates, ``rungs`` the path of
    ``rounds`` as ladder rungs (None without rounds)."""

    content: dict
    base: Result
    confirmed: list
    rungs: list | None

    @property
    def verdict(self) -> str:
        """The change the data support most, or that none does, in words."""
        return self.content["verdict"]

    @property
    def ranking(self) -> list[dict]:
        """Every candidate change, best first."""
        return self.content["ranking"]

    def to_json(self) -> dict:
        """The JSON record ``diagnose --json`` writes."""
        return self.content


def diagnose(data, model="paper", *, rounds: int | None = None, candidates=None, top: int = 3, prior=None,
             observables=None, dispersion=None, posterior: str = "laplace", seed: int = 0, out=None,
             json_path=None, wavelength_um=None, in_plane: bool = False, workers: int = 1,
             criterion: str = "loo") -> Diagnosis:
    """Which physical effect is missing or wrong: every candidate change (add, remove or replace an effect) is
    screened and the ``top`` ones refitted and compared by PSIS-LOO. ``rounds``: apply the best change and diagnose
    again, up to that many times. ``posterior``: ``laplace`` (importance-corrected, emcee where it cannot be
    trusted) or ``emcee`` for every refit. With ``out`` the figures and report.html are written there, with
    ``json_path`` the JSON record. ``data``: a Dataset, or a file read (after every other argument is checked) with
    ``wavelength_um`` and ``in_plane`` as ``load`` reads it. ``workers``: candidates searched and refitted at once,
    each in its own process (the answer does not depend on it). ``criterion``: ``loo`` (delta ELPD-LOO) or
    ``evidence`` (ln Bayes factor) ranks the refitted changes; each entry holds both where both are known."""
    from ..criticism.criteria import CRITERIA
    from ..criticism.diagnose import diagnose as run_diagnose
    from ..io.output import check_output_dir, check_output_file
    from ..physics.registry import registry

    if json_path is not None:
        check_output_file(json_path, "--json")
    if out is not None:
        check_output_dir(out)
    build_model(model)  # a wrong name fails before the data are read
    overrides = prior_overrides(prior)
    for name in candidates or []:
        registry.get(name)
    if top < 1:
        raise ParameterError(f"--top {top}: need at least 1")
    if posterior not in ("laplace", "emcee"):
        raise UnknownNameError(f"--posterior {posterior}: unknown (laplace, emcee)")
    if criterion not in CRITERIA:
        raise UnknownNameError(f"--criterion {criterion}: unknown ({', '.join(CRITERIA)})")
    if not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"--workers {workers}: need a whole number of at least 1")
    data = as_dataset(data, wavelength_um, in_plane)
    full_model = build_model(model, data, dispersion)  # over several wavelengths: n, k per wavelength
    fitted = parse_observables(observables)
    rng = np.random.default_rng(seed)
    if rounds:
        from ..criticism.rounds import as_rungs, diagnose_rounds

        content = diagnose_rounds(data, full_model, rng, rounds, seed=seed, observables=fitted, candidates=candidates,
                                  top=top, priors=overrides, posterior_method=posterior, workers=workers, criterion=criterion)
        rungs = as_rungs(content)
        base, confirmed = content.reports[0].base, content.reports[0].confirmed
    else:
        content = run_diagnose(data, full_model, rng, seed=seed, observables=fitted, candidates=candidates, top=top,
                               priors=overrides, posterior_method=posterior, workers=workers, criterion=criterion)
        base, confirmed = content.base, content.confirmed
        rungs = None
    if out is not None:
        from ..report.diagnose_report import write_diagnose_report

        write_diagnose_report(content.to_json(), base, confirmed, Path(out), data_label(data), path_rungs=rungs)
    if json_path is not None:
        from ..io.atomic import write_json

        write_json(json_path, content.to_json())
    return Diagnosis(content.to_json(), base, confirmed, rungs)


@dataclass
class Ladder:
    """The rungs of a ladder: one per model, from the start through each change in order, with its fit (ELPD-LOO
    and its difference to the rung below, reduced chi^2, the noise it infers) and its Result."""

    rungs: list

    def to_json(self) -> list[dict]:
        """The rungs as ``ladder.json`` holds them (without the Results)."""
        return [rung.to_json() for rung in self.rungs]


def ladder(data, model="paper", changes=(), *, observables=None, dispersion=None, seed: int = 0, out=None,
           json_path=None, wavelength_um=None, in_plane: bool = False) -> Ladder:
    """Fit the model and then each change in order (``"lambertian"``, ``"replace shadowing by smith"``,
    ``"remove body"``): the ladder shows what each change buys. The whole ladder is checked to compose before any
    fit. With ``out`` the figure, table and ladder.json (or ``json_path``) are written. ``data``: a Dataset, or a file
    read with ``wavelength_um`` and ``in_plane``."""
    from ..criticism.changes import parse
    from ..criticism.ladder import climb
    from ..io.output import check_output_dir, check_output_file

    if out is not None:
        check_output_dir(out)
    if json_path is not None:
        check_output_file(json_path, "--json")
    steps = list(changes)
    if not steps:
        raise ParameterError("ladder: give at least one --add CHANGE or --replay DIAGNOSE.json")
    current = build_model(model if isinstance(model, (str, Model)) else model.model)
    for step in steps:  # check the whole ladder composes before fitting anything
        current = parse(current, step).model
    data = as_dataset(data, wavelength_um, in_plane)
    rungs = climb(data, build_model(model, data, dispersion), steps, seed=seed, observables=parse_observables(observables))
    if out is not None:
        from ..report.ladder_report import write_ladder_report

        write_ladder_report(rungs, Path(out), json_path)
    return Ladder(rungs)


@dataclass
class Design:
    """Which measurements would shrink the worst-measured parameter combination most: ``content`` holds the ridge
    (its parameters, direction, SD relative to the prior), the greedy picks with the SD after each, the best single
    measurement per observable and the findings in words."""

    content: dict

    @property
    def picks(self) -> list[dict]:
        """The proposed measurements, best first."""
        return self.content["picks"]

    def to_json(self) -> dict:
        """``design.json``'s content."""
        return self.content


def design(data, model="paper", *, picks: int = 3, noise: dict | None = None, prior=None, observables=None,
           seed: int = 0, out=None, progress: bool = False) -> Design:
    """The next measurements to make: at the posterior optimum of ``model`` on ``data``, the Fisher information of
    every candidate geometry and observable; ``picks`` chosen greedily. ``noise``: {observable: level} for the
    candidates, e.g. {"dop": X, "brdf": REL, "mueller": X} (default: the data's own levels; the candidates are the
    observables that declare a ``design_noise``)."""
    from ..criticism.design import candidate_observables
    from ..criticism.design import design as rank_measurements
    from ..infer.optimum import find_optimum

    if out is not None:
        from ..io.output import check_output_dir

        out = check_output_dir(out)
    noise = dict(noise or {})
    candidates = candidate_observables()
    for name, value in noise.items():
        if name not in candidates or not (np.isfinite(float(value)) and float(value) > 0):
            raise ParameterError(f"--noise '{name}={value}': expected OBSERVABLE=X with OBSERVABLE in "
                                 f"{', '.join(candidates)} and a finite X > 0")
    if picks < 1:
        raise ParameterError(f"--picks {picks}: need at least 1")
    data = as_dataset(data)
    post = build_posterior(data, model, prior, observables)
    if progress:
        print(f"design: the optimum of {post.likelihood.model.name} on {len(data)} geometries "
              f"({', '.join(post.likelihood.observables)}), then the Fisher information of every candidate",
              file=sys.stderr)
    _, theta = find_optimum(post, np.random.default_rng(seed))
    point = {k: float(np.ravel(v)[0]) for k, v in post.priors.to_params(theta[None, :]).items()}
    content = rank_measurements(post, point, picks=picks, noise=noise)
    if out is not None:
        from ..report.design_report import write_design_report

        write_design_report(content, out, data_label(data))
    return Design(content)
