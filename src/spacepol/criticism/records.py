"""The typed records criticism returns: a candidate change as diagnose weighs it, one diagnosis, the rounds of
``diagnose --rounds`` and a ladder's rung. Each keeps its Results and posteriors as fields and gives its JSON record
with ``to_json()``; a record reads like its JSON record too (``report["verdict"]``), so that code reading the
record and code reading the JSON file look alike."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np


class _JSONView(Mapping):
    """Read access to a record through its JSON: ``record["verdict"]``, ``"ranking" in record``, ``record.get(...)``.
    ``to_json`` is ``content`` unless a record builds its JSON otherwise."""

    content: dict

    def __getitem__(self, key):
        return self.to_json()[key]

    def __iter__(self):
        return iter(self.to_json())

    def __len__(self):
        return len(self.to_json())

    def to_json(self) -> dict:
        """The record as JSON (what ``--json`` and the report files hold)."""
        return self.content


@dataclass(frozen=True, eq=False)
class CandidateFit:
    """One change of a model as diagnose weighs it: the change (``criticism.changes.Change``), its posterior,
    its screening gain (max log posterior over the base model's) and optimum, and once refitted its Result
    (``inversion``), pointwise ELPD-LOO, the differences to the base (ELPD-LOO, ln Z) and its signatures; where its
    optimum alone decides (``plugin_delta``) the plug-in log-likelihood difference instead; where a better refitted
    candidate's ELPD-LOO shows it clearly worse (``dominated_by``) its gap to that candidate instead."""

    change: object
    posterior: object
    screening_gain: float
    optimum: np.ndarray
    inversion: object | None = None
    pointwise: np.ndarray | None = None
    delta_elpd: float | None = None
    delta_elpd_se: float | None = None
    rmse_dop_after: float | None = None
    signatures: dict = field(default_factory=dict)
    significant: bool = False
    delta_log_evidence: float | None = None
    delta_log_evidence_error: float | None = None
    plugin_delta: float | None = None
    plugin_se: float | None = None
    plugin_margin: float | None = None
    dominated_by: str | None = None
    dominance_delta: float | None = None
    dominance_se: float | None = None
    dominance_margin: float | None = None

    @property
    def effect(self) -> str:
        """The effect the change adds, replaces with, or removes."""
        return self.change.effect

    @property
    def label(self) -> str:
        """The change in words ("add lambertian", "replace shadowing by smith")."""
        return self.change.label

    @property
    def model(self):
        """The changed model."""
        return self.change.model

    @property
    def kind(self) -> str:
        """``add``, ``replace`` or ``remove``."""
        return self.change.kind

    @property
    def verdict(self) -> str:
        """What diagnose's verdict says when this change leads."""
        return self.change.verdict

    @property
    def refitted(self) -> bool:
        """Whether the change was refitted (it has a Result and its ELPD-LOO difference)."""
        return self.inversion is not None


_REFITTED_ONLY = ("delta_log_evidence", "delta_log_evidence_error", "explains_misfit", "posterior", "free_parameters")
_WHERE_SET = ("tied_with", "dominated_by", "delta_to_leader", "delta_to_leader_se", "plugin_delta", "plugin_se")


@dataclass(frozen=True, eq=False)
class RankingEntry(_JSONView):
    """One change in a diagnosis's ranking, immutable: what it is (``effect``, ``change``), its differences to the
    model where refitted (ELPD-LOO with SE, ln Bayes factor with error), its screening gain, the explanation in
    words and its posterior's quality; for a change not refitted, why (``dominated_by`` the leader and the gap to
    it, or ``plugin_delta``: its optimum alone decides); for the leader, the changes ``tied_with`` it. Reads like its
    JSON entry (``entry["change"]``, ``entry.get("tied_with", [])``)."""

    effect: str
    change: str
    screening_gain: float
    explanation: str
    refitted: bool = False
    delta_elpd: float | None = None
    delta_elpd_se: float | None = None
    rmse_dop_after: float | None = None
    significant: bool = False
    delta_log_evidence: float | None = None
    delta_log_evidence_error: float | None = None
    explains_misfit: bool | None = None
    posterior: dict | None = None
    free_parameters: int | None = None
    tied_with: tuple = ()
    dominated_by: str | None = None
    delta_to_leader: float | None = None
    delta_to_leader_se: float | None = None
    plugin_delta: float | None = None
    plugin_se: float | None = None

    def to_json(self) -> dict:
        """The entry as diagnose.json holds it: the refit's fields on a refitted change, the reason on another."""
        out = {"effect": self.effect, "change": self.change, "delta_elpd": self.delta_elpd,
               "delta_elpd_se": self.delta_elpd_se, "rmse_dop_after": self.rmse_dop_after,
               "significant": self.significant}
        if self.refitted:
            out |= {k: getattr(self, k) for k in _REFITTED_ONLY[:3]}
        out |= {"screening_gain": self.screening_gain, "explanation": self.explanation}
        if self.refitted:
            out |= {k: getattr(self, k) for k in _REFITTED_ONLY[3:]}
        out |= {k: (list(v) if isinstance(v, tuple) else v) for k in _WHERE_SET if (v := getattr(self, k))
                not in (None, ())}
        return out


@dataclass(eq=False)
class DiagnosisRecord(_JSONView):
    """One diagnosis: ``content`` (the record: verdict, conclusion, ranking of ``RankingEntry``, timings), the base
    model's Result (``base``) and the refitted candidates (``confirmed``, best first)."""

    content: dict
    base: object
    confirmed: list[CandidateFit]

    def to_json(self) -> dict:
        """The record as JSON (what ``--json`` and the report files hold)."""
        return {**self.content, "ranking": [e.to_json() for e in self.content["ranking"]]}


@dataclass(frozen=True, eq=False)
class RoundStep(_JSONView):
    """One step of the path of ``diagnose --rounds``, immutable: the model after it and the ``change`` that made it
    (None for the start) with its delta ELPD-LOO and SE, the changes ``tied_with`` it and the ``alternatives``
    refitted beside it, the fit and the inferred against the measured noise, the residual structure and parameters at
    a bound; whether the change was a ``simplification`` (fewer parameters, predicting as well); on the final step,
    the slot members ``equivalent`` to the model's and those significantly ``better``. Reads like its JSON entry."""

    model: str
    change: str | None
    delta_elpd: float | None
    delta_elpd_se: float | None
    tied_with: tuple
    alternatives: tuple
    fit: dict
    inferred_noise: dict
    noise: dict
    residual_structure: tuple
    structured: bool
    at_bound: tuple
    simplification: bool | None = None
    equivalent: tuple | None = None
    better: tuple | None = None

    def to_json(self) -> dict:
        """The step as the rounds' JSON record holds it."""
        out = {"model": self.model, "change": self.change, "delta_elpd": self.delta_elpd,
               "delta_elpd_se": self.delta_elpd_se, "tied_with": list(self.tied_with),
               "alternatives": list(self.alternatives), "fit": self.fit, "inferred_noise": self.inferred_noise,
               "noise": self.noise, "residual_structure": list(self.residual_structure), "structured": self.structured,
               "at_bound": list(self.at_bound)}
        if self.simplification is not None:
            out["simplification"] = self.simplification
        if self.equivalent is not None:
            out |= {"equivalent": list(self.equivalent), "better": list(self.better or ())}
        return out


@dataclass(eq=False)
class RoundsRecord(_JSONView):
    """``diagnose --rounds``: ``content`` (the record: the path of ``RoundStep``s with the fit after each, the
    verdict, the last round's ranking) and each round's DiagnosisRecord (``reports``)."""

    content: dict
    reports: list[DiagnosisRecord]

    def to_json(self) -> dict:
        """The record as JSON (what ``--json`` and the report files hold)."""
        return {**self.content, "rounds": [step.to_json() for step in self.content["rounds"]]}


@dataclass(eq=False)
class Rung(_JSONView):
    """One rung of a ladder: ``content`` (the JSON row: model, change, ELPD-LOO and its difference to the rung below,
    reduced chi^2, inferred noise, ln Z) and the rung's Result (``inversion``)."""

    content: dict
    inversion: object
