"""How diagnose judges a refitted change against the model: the criterion that ranks the changes and calls them
significant, ELPD-LOO (``loo``, the default) or the evidence (``evidence``), each a small strategy object."""

from __future__ import annotations

MIN_DELTA_ELPD = 4.0


# Bayes factors: ln B > 3 (B > 20) is "strong" evidence on Kass & Raftery's scale (JASA 90, 773 (1995))
MIN_LOG_BAYES_FACTOR = 3.0


def significant_evidence(delta: float, error: float) -> bool:
    """A change the evidence favours: ln Bayes factor > 3 (strong, Kass & Raftery 1995) and > 2 x its error."""
    return bool(delta > MIN_LOG_BAYES_FACTOR and delta > 2 * error)


def evidence_of(result, posterior, seed: int) -> tuple[float, float]:
    """(ln Z, error) of a fit: its own where its engine gives one (Laplace-IS where its weights are trusted,
    nested sampling), else from the ``nested`` engine on the same posterior."""
    if result.log_evidence is not None:
        return result.log_evidence
    from ..infer.engine_registry import engines

    nested = engines.get("nested").result(posterior, seed=seed)
    result.summary.log_evidence = nested.summary.log_evidence
    return nested.log_evidence


def significant(delta: float, se: float) -> bool:
    """delta ELPD-LOO > 2 SE and > 4: below 4 the SE of a difference is unreliable and the models
    predict alike (Sivula, Magnusson & Vehtari 2020; Vehtari's cross-validation FAQ). Nested models
    on pure noise otherwise give tiny deltas with tinier SEs."""
    return bool(delta > 2 * se and delta > MIN_DELTA_ELPD)


class Criterion:
    """What ranks the refitted changes and calls one significant. ``skips_dominated``: whether a change its plug-in
    likelihood shows clearly worse than the refitted leader may go without a refit (an ELPD-LOO argument)."""

    name = ""
    skips_dominated = True
    note = "."  # what follows a ranking entry's ln Bayes factor

    def evidence(self, result, posterior, seed: int):
        """(ln Z, error) of a fit where its engine gave one, else None."""
        return result.log_evidence

    def judged(self, change) -> dict:
        """The fields this criterion sets on a refitted change (ELPD-LOO's verdict is the refit's own)."""
        return {}

    def order(self, change) -> float:
        """The sort key of a refitted change, best first."""
        return -change.delta_elpd


class LeaveOneOut(Criterion):
    """delta ELPD-LOO > 2 SE and > 4 (``significant``); the evidence is reported where an engine gave it."""

    name = "loo"


class Evidence(Criterion):
    """ln Bayes factor > 3 and > 2 x its error (``significant_evidence``); ln Z from Laplace-IS where trusted, else
    nested sampling, for the model and every refitted change."""

    name, skips_dominated, note = "evidence", False, " (the criterion here)."

    def evidence(self, result, posterior, seed: int):
        """(ln Z, error): the fit's own, else nested sampling's on the same posterior."""
        return evidence_of(result, posterior, seed)

    def judged(self, change) -> dict:
        """Significant by the Bayes factor."""
        return {"significant": significant_evidence(change.delta_log_evidence, change.delta_log_evidence_error)}

    def order(self, change) -> float:
        """By ln Bayes factor."""
        return -change.delta_log_evidence


CRITERION = {c.name: c for c in (LeaveOneOut(), Evidence())}
CRITERIA = tuple(CRITERION)
