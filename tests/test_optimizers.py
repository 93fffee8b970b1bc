"""The paper's GA and the other optimizers behind one interface."""

import numpy as np
import pytest

from spacepol.infer.engine_registry import OPTIMIZERS, optimize
from spacepol.infer.engines.ga import _decode
from spacepol.infer.objective import PaperObjective
from spacepol.infer.prior_set import PriorSet
from spacepol.priors import Fixed, Uniform
from spacepol.infer.engine_result import EngineResult
from spacepol.io.measurements import Dataset
from spacepol.physics import Model


@pytest.fixture(scope="module")
def objective():
    """Black-paint-like DOP, off-specular geometry, noise-free: the optimum objective is 0."""
    model = Model.from_string("paper")
    ti = np.repeat([20.0, 40.0, 60.0], 10)
    tr = np.tile(np.linspace(0, 80, 10), 3)
    data = Dataset(ti, tr, np.full(ti.size, 180.0))
    data.dop = model.evaluate({"n": 1.405, "k": 0.2289, "sigma": 0.25, "ks": 0.5, "rho_d": 0.2}, data.geometry).dop
    # fix the intensity scale (DOP only fixes k_s/rho_d) so the optimum is a point
    priors = PriorSet(model.parameters, {"ks": Fixed(0.5), "n": Uniform(1.0, 2.5), "k": Uniform(0.0, 2.0)})
    return PaperObjective(data, model, priors)


def test_ga_coding_rounds_and_spans_the_range():
    bits = 4
    chromosomes = np.array([[[0, 0, 0, 0]], [[1, 1, 1, 1]], [[0, 1, 1, 1]]], dtype=float)
    np.testing.assert_allclose(_decode(chromosomes, bits)[:, 0], [0.0, 1.0, 7 / 15])


def test_ga_follows_the_paper_settings(objective):
    res = optimize("ga", objective, np.random.default_rng(0))
    assert isinstance(res, EngineResult) and res.method == "ga"
    assert res.n_evaluations % 100 == 0 and res.n_evaluations <= 100 * 101  # population 100, <= 100 generations
    assert res.info["generations"] <= 100
    if res.info["stop_reason"] != "max_generations":
        assert res.info["stop_reason"] == "best and mean fitness within tolerance"
    assert np.all(np.diff(res.history[:, 1]) <= 0)  # best-so-far never worsens (elitism)


@pytest.mark.parametrize("method", ["de", "nlopt:GN_CRS2_LM", "nlopt:GN_MLSL_LDS", "nlopt:GN_ISRES"])
def test_global_optimizers_find_the_known_optimum(objective, method):
    res = optimize(method, objective, np.random.default_rng(1))
    assert res.objective < 1e-4, (method, res.objective, res.best)
    assert res.best["n"] == pytest.approx(1.405, abs=0.02)
    assert res.names == objective.names and res.history[-1, 0] == res.n_evaluations


def test_every_method_returns_the_same_result_type(objective):
    for method in OPTIMIZERS:
        res = optimize(method, objective, np.random.default_rng(2), max_evaluations=400) if method != "ga" else \
            optimize(method, objective, np.random.default_rng(2), max_generations=3)
        assert isinstance(res, EngineResult) and set(res.best) == set(objective.names) and res.seconds >= 0
        assert res.objective == pytest.approx(float(objective(res.best_vector()[None, :])[0]), rel=1e-9)


def test_unknown_method_is_a_clear_error(objective):
    from spacepol.errors import UnknownNameError

    with pytest.raises(UnknownNameError, match="unknown method 'bfgs'"):
        optimize("bfgs", objective, np.random.default_rng(0))
