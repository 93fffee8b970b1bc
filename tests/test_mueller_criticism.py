"""Criticism on full-Mueller data: sets rendered with NIST SCATMECH (tests/scatmech_sets.py),
base `specular`, hidden none / depolarization / extinction / subsurface. With the full matrix diagnose
names each, the twins depolarization and extinction without a tie; the same data reduced to DOP and
BRDF leave those two tied (no measurement in them separates an analyser from depolarized light)."""

import numpy as np
import pytest

from scatmech_sets import mueller_set
from spacepol.criticism.diagnose import diagnose
from spacepol.physics import Model

TWINS = ["depolarization", "extinction"]
CANDIDATES = ["depolarization", "extinction", "subsurface", "polarized_diffuse", "lambertian", "dop_bias"]


def _diagnose(kind, observables, candidates=TWINS, top=2):
    return diagnose(mueller_set(kind, seed=2), Model.from_string("specular"), np.random.default_rng(0), seed=0,
                    observables=observables, candidates=candidates, top=top, progress=False, max_steps=6000)


# extinction's half of each pair is slow (the JAX model compiles per candidate: the default suite keeps one)
@pytest.mark.parametrize("kind", ["depolarization", pytest.param("extinction", marks=pytest.mark.slow)])
def test_the_full_mueller_matrix_separates_the_twins(kind):
    """With one candidate confirmed (top 1) the twin is not refitted beside it, as it is on DOP data (the next
    test, the control): the Mueller matrix separates the two (``Effect.separated_by``), and its screening shows it."""
    report = _diagnose(kind, ["mueller", "brdf"], TWINS + ["dop_bias"], top=1)
    # a DOP estimator's bias cannot change the Mueller and BRDF likelihood: not screened, and said so
    assert [e["change"] for e in report["not_screened"]] == ["add dop_bias"]
    assert not any(r["effect"] == "dop_bias" for r in report["ranking"])
    from spacepol.report.diagnose_report import significance_statement

    assert "not screened, since they change only the measured DOP" in significance_statement(report)
    lead = report["ranking"][0]
    assert report["verdict"] == kind and not lead.get("tied_with"), (report["verdict"], lead.get("tied_with"))
    other = next(r for r in report["ranking"] if r["effect"] == {"depolarization": "extinction",
                                                                  "extinction": "depolarization"}[kind])
    assert other["delta_elpd"] is None and not other.get("dominated_by"), other
    assert lead["screening_gain"] - other["screening_gain"] > 10, (lead["screening_gain"], other["screening_gain"])


@pytest.mark.parametrize("kind", ["depolarization", pytest.param("extinction", marks=pytest.mark.slow)])
def test_dop_and_brdf_of_the_same_data_leave_them_tied(kind):
    report = _diagnose(kind, ["dop", "brdf"], TWINS + ["dop_bias"], top=1)
    # control: fitted to the DOP, the bias is a candidate like any other, and the twin is refitted beside the lead
    assert report["not_screened"] == [] and any(r["effect"] == "dop_bias" for r in report["ranking"])
    pair = {report["verdict"], *report["ranking"][0].get("tied_with", [])}
    assert pair >= {"depolarization", "extinction"}, (report["verdict"], report["ranking"][0].get("tied_with"))
    assert "full Mueller matrix" in report["ranking"][0]["explanation"]


@pytest.mark.slow  # test_the_whole_library_on_full_mueller_sets covers subsurface and none too
def test_a_hidden_subsurface_term_is_named_and_the_null_set_gets_none():
    report = _diagnose("subsurface", ["mueller", "brdf"], CANDIDATES)
    assert report["verdict"] in ("subsurface", "polarized_diffuse"), report["verdict"]
    null = _diagnose("none", ["mueller", "brdf"], CANDIDATES)
    assert null["verdict"] == "none", [(r["change"], r["delta_elpd"]) for r in null["ranking"][:3]]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["none", "depolarization", "extinction", "subsurface"])
def test_the_whole_library_on_full_mueller_sets(kind):
    """As the held-out check runs: the whole library, base `specular`, the default observables (the set holds
    DOP, BRDF and the Mueller matrix: the default fits the Mueller matrix and the BRDF, DOP being its first column)."""
    report = _diagnose(kind, None, None)
    fitted = report.base.summary.observables
    assert "brdf" in fitted and "m44" in fitted and "dop" not in fitted, fitted
    expected = {"none": {"none"}, "depolarization": {"depolarization"}, "extinction": {"extinction"},
                "subsurface": {"subsurface", "polarized_diffuse"}}[kind]
    assert report["verdict"] in expected, [(r["change"], r["delta_elpd"]) for r in report["ranking"][:4]]
    if kind in ("depolarization", "extinction"):
        assert not set(report["ranking"][0].get("tied_with", [])) & {"depolarization", "extinction"}
