"""Engines by registry: a user's sampler in one file works end to end (API and CLI) and agrees with emcee; the
built-in names, variants and kinds resolve; a wrong name, option or return value is one line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spacepol
from spacepol.errors import SpacepolError
from spacepol.infer.engine_registry import OPTIMIZERS, engines, method_names
from spacepol.priors import Fixed, Uniform

ROOT = Path(__file__).resolve().parents[1]
RANDOM_WALK = f"{ROOT / 'examples' / 'engines' / 'metropolis.py'}:RandomWalk"
PRIOR = {"ks": Fixed(0.6), "rho_d": Fixed(0.2)}
# two free parameters in narrow priors: the default suite's posterior (few nested shells, short chains)
NARROW = {"ks": Fixed(0.6), "rho_d": Fixed(0.2), "k": Fixed(0.05), "n": Uniform(1.5, 1.7), "sigma": Uniform(0.24, 0.26)}


@pytest.fixture(scope="module")
def data():
    return spacepol.synth("paper", {"n": 1.6, "sigma": 0.25, "ks": 0.6, "rho_d": 0.2}, noise_dop=0.01, noise_brdf=0.05,
                          seed=4)


@pytest.fixture(scope="module")
def reference(data):
    return spacepol.invert(data, "paper", prior=NARROW, seed=1)


def _agree(result, reference) -> dict[str, float]:
    """Per parameter: |median difference| / its Monte-Carlo standard error (1.2533 SD / sqrt(ESS), both runs)."""
    ess_a, ess_b = result.diagnostics.ess_min, reference.diagnostics.ess_min
    out = {}
    for name, draws in reference.samples(include_fixed=False).items():
        mine = result.samples()[name]
        se = 1.2533 * np.std(draws) * np.sqrt(1 / ess_a + 1 / ess_b)
        out[name] = abs(np.median(mine) - np.median(draws)) / se
    return out


def test_a_plugin_sampler_in_one_file_agrees_with_emcee(data, reference):
    result = spacepol.invert(data, "paper", prior=NARROW, engine=RANDOM_WALK, seed=1,
                             engine_options={"chains": 8, "steps": 4000})
    assert result.engine == "random_walk" and result.diagnostics.converged
    assert set(result.idata.groups()) >= {"posterior", "sample_stats", "log_likelihood", "posterior_predictive",
                                          "observed_data"}
    assert max(_agree(result, reference).values()) < 4
    # negative control: prior draws dressed as the sampler's output are far from the posterior by the same measure
    shape = result.draws.samples.shape
    prior = spacepol.build_posterior(data, "paper", NARROW).priors.sample(np.random.default_rng(0), shape[0] * shape[1])
    fake = type(result)(None, type(result.draws)(**{**result.draws.__dict__, "samples": prior.reshape(shape)}), None,
                        result.summary, {}, {})
    assert max(_agree(fake, reference).values()) > 10


def test_a_plugin_sampler_runs_from_the_command_line(tmp_path, data):
    csv = tmp_path / "d.csv"
    spacepol.synth("paper", {"n": 1.6, "sigma": 0.25}, noise_dop=0.01, noise_brdf=0.05, seed=4, out=csv)
    out = tmp_path / "run"
    from spacepol import cli

    rc = cli.main(["run", str(csv), "--engine", RANDOM_WALK, "--quiet", "--engine-option", "steps=3000",
                   "--out", str(out)])  # in this process: the command line's own code path, without a start-up
    assert rc == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["diagnostics"]["engine"] == "random_walk" and (out / "report.html").is_file()
    assert not (out / "chain.h5").exists()  # not a resumable engine
    again = spacepol.Result.load(out)
    assert again.engine == "random_walk" and again.samples()["n"].size == summary["sampler"]["chains"] * 1500


def test_names_variants_and_kinds_resolve():
    assert engines.get("emcee").kind == "sampler" and engines.get("ga").kind == "optimizer"
    assert engines.get("nlopt:GN_CRS2_LM").variant == "GN_CRS2_LM"
    assert {"ga", "de", "nlopt:GN_ESCH"} <= set(OPTIMIZERS) and "emcee" not in OPTIMIZERS
    assert {"emcee", "laplace", "nuts"} <= set(method_names())


@pytest.mark.parametrize("name, words", [
    ("hmc", "unknown engine 'hmc'"),
    ("nlopt", "needs a variant"),
    ("nlopt:LBFGS", "unknown nlopt global algorithm 'LBFGS'"),
    ("ga", "is an optimizer, not a sampler"),
    ("missing.py:X", "file missing.py not found"),
])
def test_wrong_engine_names_are_one_line(data, name, words):
    with pytest.raises(SpacepolError) as caught:
        spacepol.invert(data, "paper", engine=name)
    assert words in str(caught.value) and len(str(caught.value).splitlines()) == 1


def test_wrong_options_and_broken_engines_are_one_line(tmp_path, data):
    with pytest.raises(SpacepolError, match="engine nuts: no option 'walkers'"):
        spacepol.invert(data, "paper", engine="nuts", walkers=16)
    broken = tmp_path / "broken.py"
    broken.write_text("import numpy as np\nfrom spacepol.infer.engines.base import Engine\n"
                      "from spacepol.infer.engine_result import EngineResult\n"
                      "class Flat(Engine):\n    name = 'flat'\n"
                      "    def run(self, posterior, rng):\n"
                      "        return EngineResult('flat', '', list(posterior.names), {}, 0.0, '', 0, 0.0, 0,\n"
                      "                            samples=np.zeros((10, posterior.ndim)), log_prob=np.zeros(10))\n")
    with pytest.raises(SpacepolError, match=r"engine flat: samples of shape \(10, 5\)"):
        spacepol.invert(data, "paper", engine=f"{broken}:Flat")
    r = subprocess.run([sys.executable, "-m", "spacepol.cli", "run", "x.csv", "--engine", "hmc", "--out",
                        str(tmp_path / "r")], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2 and "unknown engine 'hmc'" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "r").exists()


def _importance_log_evidence(data, prior, reference, draws: int = 40000):
    """ln Z by importance sampling from a Student-t fitted to emcee's draws (an estimate independent of nested
    sampling), and its standard error."""
    from scipy import stats
    from scipy.special import logsumexp

    post = spacepol.build_posterior(data, "paper", prior)
    flat = reference.draws.flat_samples()
    proposal = stats.multivariate_t(flat.mean(0), np.cov(flat.T) * 1.5, df=5, seed=3)
    x = proposal.rvs(draws)
    log_w = post.log_prob(x) - proposal.logpdf(x)  # ln prior (normalised) + ln L - ln q
    log_w = np.where(np.isfinite(log_w), log_w, -np.inf)
    w = np.exp(log_w - log_w.max())
    return float(logsumexp(log_w) - np.log(draws)), float(np.std(w) / np.sqrt(draws) / np.mean(w))


def _check_nested(data, prior, wider, reference, options):
    """ln Z of ``nested`` within 4 combined SE of importance sampling, its draws as emcee's; control: a prior twice
    as wide in sigma (``wider``) moves ln Z by ln 2 and fails the same comparison."""
    result = spacepol.invert(data, "paper", prior=prior, engine="nested", seed=1, engine_options=options)
    (log_z, error), (expected, expected_se) = result.log_evidence, _importance_log_evidence(data, prior, reference)
    assert np.isfinite(error) and error > 0 and result.summary.log_evidence["error"] == error
    tolerance = 4 * np.hypot(error, expected_se)
    assert abs(log_z - expected) < tolerance
    assert max(_agree(result, reference).values()) < 4 and result.diagnostics.rhat_max < 1.01
    assert "missed_mode" not in result.summary.sampler  # the control of the missed-mode check below
    other, _ = _importance_log_evidence(data, {**prior, "sigma": wider}, reference)
    assert abs(other - (expected - np.log(2))) < 4 * expected_se and abs(log_z - other) > tolerance


def test_nested_sampling_gives_the_evidence_and_the_posterior_fast(data, reference):
    """Two free parameters with narrow priors (few shells: fast)."""
    _check_nested(data, NARROW, Uniform(0.235, 0.275), reference, {"live": 200, "replicates": 3, "effective_draws": 800})


def test_nested_sampling_that_missed_the_best_mode_says_so(data, monkeypatch):
    """The posterior's mode lies far above every draw nested sampling returned (its draws replaced here by draws
    of the prior around n 1.52, 40 posterior SDs from the mode): the run says its ln Z covers only the modes it
    found, in the summary and the report's verdict. The control (the true draws: nothing missed) is in the test
    above."""
    from spacepol.infer.engines import nested as nested_module

    real = nested_module.sample_nested

    def stranded(posterior, rng, **options):
        draws = real(posterior, rng, **options)
        far = draws.samples.copy()
        far[..., posterior.names.index("n")] = 1.52 + 0.001 * rng.standard_normal(far.shape[:2])
        draws.samples, draws.log_prob = far, posterior.log_prob(far.reshape(-1, far.shape[-1])).reshape(far.shape[:2])
        return draws

    monkeypatch.setattr(nested_module, "sample_nested", stranded)
    result = spacepol.invert(data, "paper", prior=NARROW, engine="nested", seed=1,
                             engine_options={"live": 100, "replicates": 2, "effective_draws": 300})
    missed = result.summary.sampler["missed_mode"]
    assert missed["log_posterior"] > missed["best_sampled"] + 4 and abs(missed["at"]["n"] - 1.6) < 0.02
    assert "ln Z covers only the modes it found" in missed["finding"]


@pytest.mark.slow
def test_nested_sampling_gives_the_evidence_and_the_posterior(data):
    """Three free parameters with their default priors."""
    reference = spacepol.invert(data, "paper", prior=PRIOR, seed=1)
    _check_nested(data, PRIOR, Uniform(0.02, 1.58), reference, {"live": 200, "replicates": 3, "effective_draws": 800})


def test_sampling_after_the_exploration_stops_at_its_likelihood_budget():
    """``explore_then_sample``: on a posterior far narrower than the prior the sampling phase stops after its budget of
    likelihood calls per live point, short of an unreachable number of effective draws, and says so; a reachable
    number is reached (control) within the same budget."""
    from nautilus import Sampler

    from spacepol.infer.engines.nested import explore_then_sample
    from spacepol.infer.engines.stall_guard import CallClock

    class Counted(Sampler):
        def run(self, **options):
            self.calls_before.append(self.n_like)
            return super().run(**options)

    clock = CallClock()

    def log_likelihood(x):
        clock.tick()
        return -0.5 * np.sum(((x - 0.5) / 0.03) ** 2, axis=-1)

    def sampler():
        s = Counted(lambda u: u, log_likelihood, n_dim=2, n_live=50, n_networks=1, vectorized=True, seed=3)
        s.calls_before = []
        return s

    capped = sampler()
    outcome = explore_then_sample(capped, effective_draws=10**6, clock=clock, what="test", calls_per_live_point=4)
    assert outcome.explored and not outcome.draws_reached
    spent = capped.n_like - capped.calls_before[-1]  # the sampling phase, the last run
    assert 4 * 50 <= spent <= 4 * 50 + 50, (capped.calls_before, spent)  # nautilus stops at the first batch past it
    reached = sampler()
    outcome = explore_then_sample(reached, effective_draws=150, clock=clock, what="test", calls_per_live_point=4)
    assert outcome.explored and outcome.draws_reached, reached.n_eff


def test_an_exploration_that_adds_no_shell_is_ended_where_it_stands_and_its_evidence_still_holds():
    """``explore_then_sample`` ends an exploration that adds no shell in ``stuck_calls_per_live_point`` calls per live
    point (nautilus rejecting every new bound as no smaller: here forced after three shells) and samples the shells it
    has; ln Z of a 2-d Gaussian (sigma 0.03 in the unit square: ln 2 pi sigma^2 = -5.175) still within 0.4 of the truth
    (between seeds it scatters by 0.08 so stopped; 0.01 when explored). Controls: unforced, the exploration ends by
    nautilus' own criterion under the same limit, and in steps it leaves the very points one run does."""
    from nautilus import Sampler

    from spacepol.infer.engines.nested import _explore, explore_then_sample
    from spacepol.infer.engines.stall_guard import CallClock

    clock = CallClock()

    def log_likelihood(x):
        clock.tick()
        return -0.5 * np.sum(((x - 0.5) / 0.03) ** 2, axis=-1)

    class Stuck(Sampler):
        def add_bound(self, verbose=False):
            if len(self.bounds) >= 3:
                return False
            self.last_shell_at = self.n_like
            return super().add_bound(verbose)

        def run(self, **options):
            self.sampling_from = self.n_like  # the last run samples the shells
            return super().run(**options)

    def run(kind):
        s = kind(lambda u: u, log_likelihood, n_dim=2, n_live=50, n_networks=1, vectorized=True, seed=0)
        return s, explore_then_sample(s, 800, clock, "test", calls_per_live_point=40, stuck_calls_per_live_point=20)

    stuck, outcome = run(Stuck)
    assert not outcome.explored and stuck.explored and len(stuck.bounds) == 3
    exploring = stuck.sampling_from - stuck.last_shell_at  # from the last shell to the end of the exploration
    # the limit (1,000), the batch (100) of the step that added the shell and the one that ends it, a batch to fill
    # each shell: 1,500 at most; a batch more as margin
    assert 20 * 50 <= exploring <= 20 * 50 + 2 * 100 + 3 * 100 + 100, exploring
    assert abs(stuck.log_z - np.log(2 * np.pi * 0.03**2)) < 0.4, stuck.log_z
    one = Sampler(lambda u: u, log_likelihood, n_dim=2, n_live=50, n_networks=1, vectorized=True, seed=1)
    stepped = Sampler(lambda u: u, log_likelihood, n_dim=2, n_live=50, n_networks=1, vectorized=True, seed=1)
    one.run(n_eff=0, discard_exploration=True, verbose=False)
    assert _explore(stepped, 20 * 50)  # the same limit: ended by nautilus' own criterion, with more than 3 shells
    assert len(stepped.bounds) > 3
    assert one.n_like == stepped.n_like and np.array_equal(one.posterior()[0], stepped.posterior()[0])
