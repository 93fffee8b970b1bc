"""The run summary is one typed record, written and read in ``infer.run_summary`` only."""

import re
from pathlib import Path

import pytest

from spacepol.errors import SpacepolError
from spacepol.infer.run_summary import RunSummary

SRC = Path(__file__).resolve().parents[1] / "src" / "spacepol"
FIXED = ("model", "spec", "parameters", "diagnostics", "fit", "seconds", "seed", "observables", "priors", "fixed", "map",
         "sampler", "identifiability")


def test_summary_json_round_trips_with_its_fixed_fields_and_keeps_unknown_ones():
    content = {"model": "paper", "spec": {"effects": "paper"}, "parameters": {"n": {"median": 1.5}},
               "diagnostics": {"engine": "emcee", "rhat_max": 1.003}, "fit": {"elpd_loo": -12.5}, "seconds": 3.0,
               "seed": 7, "observables": ["dop"], "priors": {"n": "Uniform(0.1, 5)"}, "fixed": {}, "map": {"n": 1.49},
               "sampler": {"walkers": 32}, "identifiability": {"at_bound": [{"parameter": "k"}]},
               "written_by_a_later_version": [1, 2]}
    summary = RunSummary.from_json(content)
    assert summary.seed == 7 and summary.engine_ran == "emcee" and summary.at_bound == [{"parameter": "k"}]
    assert summary.extra == {"written_by_a_later_version": [1, 2]}
    again = summary.to_json()
    assert all(k in again for k in FIXED)
    assert {k: again[k] for k in content} == content
    # the optional fields are written only where they hold something
    assert "log_evidence" not in again and "laplace_refused" not in again
    summary.laplace_refused = "Pareto k 0.9 > 0.7"
    assert summary.to_json()["laplace_refused"] == "Pareto k 0.9 > 0.7"


@pytest.mark.parametrize("content", [None, [], {"parameters": {}}, {"model": 3}])
def test_what_is_not_a_summary_is_one_line_naming_the_file(content):
    with pytest.raises(SpacepolError, match=r"^runs/x/summary.json: not a spacepol summary"):
        RunSummary.from_json(content, "runs/x/summary.json")


def _keyed_reads(text: str) -> list[str]:
    return re.findall(r"summary\[[\"']\w+[\"']\]|summary\.get\([\"']\w+[\"']", text)


def test_no_module_reads_the_summary_by_string_key():
    offenders = {str(p.relative_to(SRC)): _keyed_reads(p.read_text()) for p in SRC.rglob("*.py")
                 if p.name != "run_summary.py"}
    assert {k: v for k, v in offenders.items() if v} == {}


def test_the_key_check_sees_a_keyed_read():
    """Negative control: the pattern the check looks for is found where it is."""
    assert _keyed_reads('x = result.summary["fit"]["chi2_red"]; y = summary.get("noise", {})') == \
        ['summary["fit"]', 'summary.get("noise"']
