"""The typed records criticism returns: a candidate change as diagnose weighs it, one diagnosis, the rounds of
``diagnose --rounds`` and a ladder's rung. Each keeps its Results and posteriors as fields and gives its JSON record
with ``to_json()``; a record reads like its JSON record too (``report["verdict"]``), so that code reading the
record and code reading the JSON file look alike."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np


class _JSONView(Mapping):
    """Read access to a record's JSON content: ``record["verdict"]``, ``"ranking" in record``, ``record.get(...)``."""

    content: dict

    def __getitem__(self, key):
        return self.content[key]

    def __iter__(self):
        return iter(self.content)

    def __len__(self):
        return len(self.content)

    def to_json(self) -> dict:
        """The record as JSON (what ``--json`` and the report files hold)."""
        return self.content


@dataclass(eq=False)
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


@dataclass(eq=False)
class DiagnosisRecord(_JSONView):
    """One diagnosis: ``content`` (the JSON record: verdict, conclusion, ranking, timings), the base model's Result
    (``base``) and the refitted candidates (``confirmed``, best first)."""

    content: dict
    base: object
    confirmed: list[CandidateFit]


@dataclass(eq=False)
class RoundsRecord(_JSONView):
    """``diagnose --rounds``: ``content`` (the JSON record: the path of changes with the fit after each, the verdict,
    the last round's ranking) and each round's DiagnosisRecord (``reports``)."""

    content: dict
    reports: list[DiagnosisRecord]


@dataclass(eq=False)
class Rung(_JSONView):
    """One rung of a ladder: ``content`` (the JSON row: model, change, ELPD-LOO and its difference to the rung below,
    reduced chi^2, inferred noise, ln Z) and the rung's Result (``inversion``)."""

    content: dict
    inversion: object
