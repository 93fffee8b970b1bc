"""A run's summary as one typed record (``RunSummary``), written to and read from ``summary.json`` here and nowhere
else: the fields DESIGN.md fixes (model, spec, parameters, diagnostics, fit, seconds, seed, observables, priors,
fixed, map, sampler, identifiability) and the optional ones (evidence, noise, derived values, references, why the
Laplace approximation was refused). Fields another version wrote that this one does not know are kept as they were."""

from __future__ import annotations

from dataclasses import dataclass, field, fields

from ..errors import SpacepolError

# written only where they hold something (a run without them writes no such key)
_OPTIONAL = ("log_evidence", "start_search", "noise", "derived", "references", "laplace_refused")


@dataclass
class RunSummary:
    """What one inversion found and how: quantiles of every parameter (``parameters``, ``derived``), the fit
    (chi2, RMSE, ELPD-LOO), the engine's diagnostics and settings, the model (``spec``) and priors it ran with, the
    inferred against the measured noise (``noise``), identifiability and residual structure, and the evidence
    where an engine estimates it. ``extra``: fields of a summary.json this version does not know, kept."""

    model: str
    spec: dict | str | None = None
    parameters: dict = field(default_factory=dict)
    engine: str = ""
    diagnostics: dict = field(default_factory=dict)
    fit: dict = field(default_factory=dict)
    seconds: float = 0.0
    seed: int = -1
    observables: list = field(default_factory=list)
    observables_not_fitted: dict = field(default_factory=dict)
    observable_plugins: dict = field(default_factory=dict)
    n_observations: int = 0
    priors: dict = field(default_factory=dict)
    fixed: dict = field(default_factory=dict)
    map: dict = field(default_factory=dict)
    sampler: dict = field(default_factory=dict)
    pareto_k_bad: list = field(default_factory=list)
    log_evidence: dict | None = None
    start_search: dict = field(default_factory=dict)
    noise: dict = field(default_factory=dict)
    derived: dict = field(default_factory=dict)
    identifiability: dict = field(default_factory=dict)
    residual_structure: dict = field(default_factory=dict)
    references: dict = field(default_factory=dict)
    laplace_refused: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def model_spec(self) -> dict | str:
        """The whole model as ``physics.model_spec`` writes it, or its name where an older summary has no spec."""
        return self.spec if self.spec is not None else self.model

    @property
    def engine_ran(self) -> str:
        """The engine that drew the posterior (emcee where the Laplace approximation was refused)."""
        return str(self.diagnostics.get("engine") or self.engine)

    @property
    def at_bound(self) -> list:
        """The parameters whose posterior piles at a prior bound (identifiability's findings)."""
        return list(self.identifiability.get("at_bound", []))

    @property
    def residual_findings(self) -> list[str]:
        """The residual structure in words."""
        return list(self.residual_structure.get("findings", []))

    @property
    def residuals_structured(self) -> bool:
        """Whether the residuals are structured (runs or lag-1 correlation beyond chance)."""
        return bool(self.residual_structure.get("structured", False))

    def to_json(self) -> dict:
        """summary.json's content: the fixed fields in their order, the optional ones where they hold something,
        then the unknown ones kept from the file read."""
        out = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "extra" or (f.name in _OPTIONAL and not value):
                continue
            if f.name == "spec" and value is None:
                continue
            out[f.name] = value
        return out | self.extra

    @classmethod
    def from_json(cls, content, where: str = "summary.json") -> "RunSummary":
        """The record of summary.json's ``content``; one line naming ``where`` when it is not a spacepol summary."""
        if not isinstance(content, dict) or not isinstance(content.get("model"), str):
            raise SpacepolError(f"{where}: not a spacepol summary (no 'model')")
        known = {f.name for f in fields(cls)} - {"extra"}
        return cls(**{k: v for k, v in content.items() if k in known},
                   extra={k: v for k, v in content.items() if k not in known})
