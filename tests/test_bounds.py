"""A posterior piled against a prior bound is flagged and never called well constrained."""

from types import SimpleNamespace

import numpy as np

from spacepol.infer.identifiability import at_bounds, bound_finding
from spacepol.infer.prior_set import PriorSet
from spacepol.physics import Model


def _posterior():
    model = Model.from_string("paper")
    return SimpleNamespace(priors=PriorSet(model.parameters))


def _flat(post, **columns):
    rng = np.random.default_rng(1)
    names = post.priors.names
    mid = {n: 0.5 * sum(post.priors.priors[n].bounds) for n in names}
    return np.column_stack([columns.get(n, mid[n] + 1e-3 * rng.standard_normal(4000)) for n in names]), names


def test_a_posterior_cut_off_by_the_prior_is_flagged_and_one_inside_is_not():
    post = _posterior()
    lo_n = post.priors.priors["n"].lower
    rng = np.random.default_rng(0)
    piled = lo_n + np.abs(0.02 * rng.standard_normal(4000))  # a half-normal against the bound: PTFE's n
    flat, names = _flat(post, n=piled)
    flags = at_bounds(post, flat, names)
    assert [(f["parameter"], f["side"]) for f in flags] == [("n", "lower")]
    text = bound_finding(flags[0])
    assert f"n sits at its lower bound {lo_n:g}" in text and "the model or the prior is wrong" in text

    # negative controls: narrow and well inside (10 sd from the bound), and flat over the whole prior
    near = lo_n + 0.1 + 0.01 * rng.standard_normal(4000)
    flat_prior = post.priors.priors["n"].sample(rng, 4000)
    for column in (near, flat_prior):
        flat, names = _flat(post, n=column)
        assert at_bounds(post, flat, names) == []


def test_the_physical_limit_is_worded_as_such():
    post = _posterior()
    rng = np.random.default_rng(2)
    flat, names = _flat(post, k=np.abs(0.05 * rng.standard_normal(4000)))
    (flag,) = at_bounds(post, flat, names)
    assert flag["parameter"] == "k" and flag["physical_limit"]
    assert "reaches its physical limit 0" in bound_finding(flag)


def test_identifiability_never_calls_a_flagged_parameter_well_constrained():
    from spacepol.infer.identifiability import identifiability

    post = _posterior()
    from spacepol.observables import get

    post.likelihood = SimpleNamespace(observables=["dop", "brdf"], objects=[get("dop"), get("brdf")],
                                      model=Model.from_string("paper"))
    rng = np.random.default_rng(3)
    flat, names = _flat(post, n=post.priors.priors["n"].lower + np.abs(0.02 * rng.standard_normal(4000)))
    result = SimpleNamespace(flat_samples=lambda: flat, names=names)
    findings = identifiability(post, result)["findings"]
    assert any("sits at its lower bound" in f for f in findings)
    assert not any("well constrained" in f for f in findings)


def test_the_ladder_table_shows_the_inferred_noise_when_the_file_gives_none():
    """With inferred noise chi^2 ~ 1 by construction: the table shows the inferred noise per rung and says why."""
    from spacepol.report.ladder_report import ladder_table

    rungs = [{"model": m, "rmse_dop": 0.01, "chi2_red": 1.0, "elpd_loo": e, "elpd_loo_se": 1.0, "rhat_max": 1.0,
              "inferred_noise": {"sigma_dop": s, "sigma_brdf_rel": b}} for m, e, s, b in
             [("paper", 384.4, 0.0083, 0.19), ("paper+polarized_diffuse", 473.9, 0.0167, 0.039)]]
    text = "\n".join(ladder_table(rungs))
    assert "sigma_dop (inferred)" in text and "sigma_brdf_rel (inferred)" in text and "0.039" in text
    assert "by construction" in text
    known = [{k: v for k, v in r.items() if k != "inferred_noise"} for r in rungs]  # control: known noise
    assert "inferred" not in "\n".join(ladder_table(known))


def test_the_ladder_table_names_each_rungs_posterior_check():
    """A rung fitted by emcee shows its R-hat; one diagnose fitted by Laplace + PSIS (no R-hat) its Pareto k."""
    from spacepol.report.ladder_report import ladder_table

    base = {"rmse_dop": 0.01, "chi2_red": 1.0, "elpd_loo_se": 1.0, "inferred_noise": {}}
    rungs = [{**base, "model": "paper", "elpd_loo": 384.4, "rhat_max": 1.004},
             {**base, "model": "paper+ggx", "elpd_loo": 400.0, "rhat_max": None, "pareto_k": 0.31}]
    text = "\n".join(ladder_table(rungs))
    assert "R-hat 1.004" in text and "Laplace-IS, Pareto k 0.31" in text
