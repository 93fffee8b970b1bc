"""`invert-mcmc run`, `optimize` and `compare` end to end, and their bad-input errors."""

import json

import arviz as az
import pytest

from spacepol.paths import bundled
from cli_runner import run_cli

PTFE = str(bundled("ptfe", "ptfe_mueller_brdf.csv"))


def cli(*args, cwd=None):
    """The command line in this process (``cli_runner``): its exit status, stdout and stderr."""
    return run_cli(*args, cwd=cwd)


@pytest.fixture(scope="module")
def run_out(tmp_path_factory):
    """A well-identified set (DOP and BRDF, specular+smith): converges quickly."""
    tmp = tmp_path_factory.mktemp("run")
    data = tmp / "al.csv"
    assert cli("synth", "--model", "specular+smith", "--set", "n=1.5", "--set", "k=0.5", "--set", "sigma=0.2",
               "--set", "ks=0.8", "--noise-dop", "0.01", "--noise-brdf", "0.05", "--seed", "3", "--out", data).returncode == 0
    out = tmp / "out"
    run = cli("run", data, "--model", "specular+smith", "--seed", "1", "--quiet", "--out", out)
    assert run.returncode == 0, run.stderr
    return out


def test_run_writes_the_design_outputs(run_out):
    out = run_out
    for name in ("summary.json", "posterior.nc", "corner.png", "fit.png", "residuals.png", "residual_trends.png", "report.html"):
        assert (out / name).stat().st_size > 0, name
    s = json.loads((out / "summary.json").read_text())
    assert s["model"] == "specular+smith"
    assert set(s["parameters"]) == {"n", "k", "sigma", "ks"}
    for q in s["parameters"].values():
        assert set(q) >= {"median", "q05", "q16", "q84", "q95"} and q["q05"] <= q["q16"] <= q["median"] <= q["q84"] <= q["q95"]
    assert set(s["diagnostics"]) >= {"rhat_max", "ess_min", "tau_max", "acceptance"}
    assert set(s["fit"]) >= {"rmse_dop", "chi2_red", "elpd_loo", "elpd_loo_se"}
    assert s["seconds"] > 0 and s["diagnostics"]["rhat_max"] <= 1.01 and s["diagnostics"]["ess_min"] >= 400
    idata = az.from_netcdf(out / "posterior.nc")
    for group in ("posterior", "posterior_predictive", "log_likelihood", "sample_stats", "observed_data"):
        assert group in idata.groups(), group
    assert idata.posterior.attrs["seed"] == 1
    assert "truth" in (out / "report.html").read_text()


def test_run_explains_the_dop_only_degeneracy(tmp_path):
    """DOP-only data (black paint, off-specular) and the paper model: the report says only k_s/rho_d is measured.
    (A short capped chain: the finding does not need a converged one, and the report says it is not.)"""
    data = tmp_path / "al.csv"
    assert cli("synth", "--model", "paper", "--set", "n=1.405", "--set", "k=0.2289", "--set", "sigma=0.25",
               "--set", "ks=0.5", "--set", "rho_d=0.2", "--noise-dop", "0.005", "--seed", "3", "--out", data).returncode == 0
    out = tmp_path / "out"
    run = cli("run", data, "--model", "paper", "--steps", "2500", "--quiet", "--out", out)
    assert run.returncode == 0, run.stderr
    s = json.loads((out / "summary.json").read_text())
    findings = " ".join(s["identifiability"]["findings"])
    assert "only the ratio k_s/rho_d is measured" in findings and "Add BRDF" in findings
    html = (out / "report.html").read_text()
    assert "only the ratio k_s/rho_d is measured" in html and "data:image/png;base64" in html
    assert s["sampler"]["capped"] and "hit the step cap" in html


def test_rerun_of_a_finished_run_reports_again_and_a_different_run_is_refused(run_out):
    """The same command on a finished run: no new steps, the report written again, exit 0 (resuming an
    interrupted chain is tested with real kills in test_recovery.py); a different run on that folder
    is refused with the remedy."""
    import emcee

    before = emcee.backends.HDFBackend(str(run_out / "chain.h5"), name="mcmc", read_only=True).iteration
    data = run_out.parent / "al.csv"
    run = cli("run", data, "--model", "specular+smith", "--seed", "1", "--out", run_out)
    assert run.returncode == 0 and "is complete" in run.stderr, run.stderr
    after = emcee.backends.HDFBackend(str(run_out / "chain.h5"), name="mcmc", read_only=True).iteration
    assert after == before
    clash = cli("run", data, "--model", "specular+smith", "--seed", "2", "--quiet", "--out", run_out)
    assert clash.returncode == 2 and "holds the chain of a different run" in clash.stderr and "--restart" in clash.stderr


@pytest.mark.slow
def test_ptfe_run_converges_and_explains_the_index(tmp_path):
    """Acceptance: NIST PTFE, 0.633 um, in-plane: R-hat <= 1.01, ESS >= 400, and the report
    says how the inferred n relates to PTFE's bulk index (about 1.35). By default the whole measured
    Mueller matrix is fitted (with the BRDF); DOP and q, u are its first column, so not fitted again."""
    out = tmp_path / "ptfe"
    run = cli("run", PTFE, "--wavelength-um", "0.633", "--in-plane", "--reference", "n=1.35", "--quiet", "--out", out)
    assert run.returncode == 0, run.stderr
    s = json.loads((out / "summary.json").read_text())
    assert s["diagnostics"]["rhat_max"] <= 1.01 and s["diagnostics"]["ess_min"] >= 400
    assert "m44" in s["observables"] and "brdf" in s["observables"] and "dop" not in s["observables"]
    assert s["observables_not_fitted"] == {"dop": "mueller", "stokes": "mueller"}
    ref = s["references"]["n"]
    assert "1.35" in ref["explanation"]
    # The paper's model, whose only polarizing term is the specular lobe, cannot place PTFE's
    # index at 1.35: the posterior excludes it and the report says the model is what is wrong.
    assert not ref["consistent"] and "model that is wrong" in ref["explanation"]
    # and the residuals say the misfit is smooth: the BRDF's U shape (the body term's cos(theta_r))
    assert s["residual_structure"]["runs"]["brdf"]["p"] < 0.01
    assert "model that is wrong" in (out / "report.html").read_text()
    # the diffuse weight piles against its bound 1, a reflectance's limit (a Lambertian-like PTFE asks for more than the
    # paper's cos(theta_r) body term gives): flagged, and never called well constrained
    flags = s["identifiability"]["at_bound"]
    assert any(f["parameter"] == "rho_d" and f["side"] == "upper" for f in flags), flags
    assert "rho_d reaches its physical limit 1" in (out / "report.html").read_text()  # a reflectance of 1
    assert not any("well constrained" in f for f in s["identifiability"]["findings"])


def test_ptfe_run_by_laplace_explains_the_index(tmp_path):
    """The fast version of the test above (Laplace-IS instead of emcee: the same posterior, its own diagnostics):
    the report says the model is wrong, the BRDF's residuals are structured, rho_d is at its physical limit."""
    out = tmp_path / "ptfe"
    run = cli("run", PTFE, "--wavelength-um", "0.633", "--in-plane", "--reference", "n=1.35", "--engine", "laplace",
              "--quiet", "--out", out)
    assert run.returncode == 0, run.stderr
    s = json.loads((out / "summary.json").read_text())
    d = s["diagnostics"]
    # the walkers' spread over the importance draws sits near its limit here (1.075 x against 1.08 on an Intel Xeon):
    # either engine is a right outcome, as long as the run says which one ran and why
    if s["engine"] == "laplace-is":
        from spacepol.infer.spread_check import BOUNDED_K, MAX_SD_GROWTH

        assert d["pareto_k"] < 0.7 and d["ess_min"] >= 100, d
        # the walkers ran and kept the width, or the weights were bounded and they were not needed
        assert (d["sd_growth_max"] <= MAX_SD_GROWTH if d["sd_growth_max"] is not None else d["pareto_k"] <= BOUNDED_K), d
    else:
        assert s["engine"] == "emcee" and "spread" in s["laplace_refused"] and d["rhat_max"] < 1.05, (s["engine"], d)
    assert s["observables_not_fitted"] == {"dop": "mueller", "stokes": "mueller"}
    ref = s["references"]["n"]
    assert not ref["consistent"] and "model that is wrong" in ref["explanation"] and "1.35" in ref["explanation"]
    assert s["residual_structure"]["runs"]["brdf"]["p"] < 0.01
    flags = s["identifiability"]["at_bound"]
    assert any(f["parameter"] == "rho_d" and f["side"] == "upper" for f in flags), flags
    assert "rho_d reaches its physical limit 1" in (out / "report.html").read_text()


def test_optimize_prints_json():
    run = cli("optimize", PTFE, "--wavelength-um", "0.633", "--in-plane", "--method", "nlopt:GN_DIRECT_L")
    assert run.returncode == 0, run.stderr
    result = json.loads(run.stdout)
    assert result["method"] == "nlopt:GN_DIRECT_L" and set(result["best"]) == {"n", "k", "sigma", "ks", "rho_d"}
    assert result["n_evaluations"] > 0 and result["objective_name"] == "eq25_relative_squared_error"


def test_compare_writes_table_json_and_figure(tmp_path):
    run = cli("compare", PTFE, "--wavelength-um", "0.633", "--in-plane", "--methods", "de", "nlopt:GN_DIRECT_L",
              "--seeds", "2", "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    report = json.loads((tmp_path / "optimizers.json").read_text())
    rows = {r["method"]: r for r in report["methods"]}
    assert set(rows) == {"de", "nlopt:GN_DIRECT_L"} and all(r["runs"] == 2 for r in rows.values())
    assert min(r["best_objective"] for r in rows.values()) == pytest.approx(report["best_known"])
    assert (tmp_path / "optimizers.png").stat().st_size > 0
    assert "| de |" in (tmp_path / "optimizers.md").read_text()


@pytest.mark.parametrize("args,message", [
    (["optimize", PTFE, "--wavelength-um", "0.633", "--method", "simplex"], "unknown method 'simplex'"),
    (["optimize", PTFE, "--wavelength-um", "0.633", "--method", "nlopt:GN_MAGIC"], "unknown nlopt global algorithm"),
    (["run", PTFE, "--wavelength-um", "0.633", "--model", "paper+glitter"], "unknown effect 'glitter'"),
    (["run", PTFE], "several wavelengths"),
    (["run", PTFE, "--wavelength-um", "0.5"], "no rows at wavelength 0.5"),
])
def test_bad_inference_input(tmp_path, args, message):
    out = tmp_path / "never"
    run = cli(*args, *(["--out", out] if args[0] == "run" else []))
    assert run.returncode == 2, run.stderr
    assert message in run.stderr and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_impossible_prior_and_too_few_points(tmp_path):
    prior = tmp_path / "p.toml"
    prior.write_text("[sigma]\nlower = 0.5\nupper = 0.1\n")
    run = cli("run", PTFE, "--wavelength-um", "0.633", "--prior", prior, "--out", tmp_path / "o")
    assert run.returncode == 2 and "[sigma]" in run.stderr and "not below upper bound" in run.stderr
    small = tmp_path / "small.csv"
    small.write_text("theta_i,theta_r,dop\n30,10,0.1\n30,20,0.12\n30,30,0.15\n")
    run = cli("run", small, "--out", tmp_path / "o")
    assert run.returncode == 2 and "3 observations are fewer than the 6 free parameters" in run.stderr
    assert not (tmp_path / "o").exists()
