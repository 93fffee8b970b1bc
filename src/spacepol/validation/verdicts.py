"""The validation suites' answers as a record later code must give again: per hidden-effect case the verdict and the
twins tied with it, per swap case the path of changes and the final model. A change meant to make diagnose faster
(not to change what it finds) is checked against the record its code made before (``differences``)."""

from __future__ import annotations


def verdicts(rows: list[dict], swap_rows: list[dict]) -> dict:
    """The answers of scored suite rows (``hidden_effects.run_suite``, ``swap_suite.run_swap_case``):
    ``{"hidden": {label: {"verdict", "tied_with"}}, "swaps": {label: {"path", "final_model"}}}``."""
    return {"hidden": {r["label"]: {"verdict": r["verdict"], "tied_with": sorted(r["tied_with"])} for r in rows},
            "swaps": {r["label"]: {"path": list(r["path"]), "final_model": r["final_model"]} for r in swap_rows}}


def differences(found: dict, reference: dict, part: str) -> list[str]:
    """Each case of ``part`` (``hidden`` or ``swaps``) in ``found`` whose answer is not the ``reference``'s, in words;
    a case of the reference that ``found`` lacks, or one the reference lacks, counts too."""
    ours, theirs = found.get(part, {}), reference.get(part, {})
    out = [f"{label}: missing (reference: {theirs[label]})" for label in sorted(set(theirs) - set(ours))]
    out += [f"{label}: not in the reference" for label in sorted(set(ours) - set(theirs))]
    out += [f"{label}: {ours[label]} (reference: {theirs[label]})" for label in sorted(set(ours) & set(theirs))
            if ours[label] != theirs[label]]
    return out
