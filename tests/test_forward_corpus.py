"""The JAX forward model reproduces the numpy/numba implementation it replaced (``tests/data/forward_corpus.npz``,
recorded by ``tests/data/make_forward_corpus.py`` at commit 7870214) to 1e-12: Stokes vectors, Mueller
matrices and DOP for every built-in effect over the whole prior support, special geometries included. The one
intended change since: ``subsurface``'s internal reflectance is now the exact average, where the corpus summed it
on SCATMECH's 0.2 deg grid; its albedo is mapped so that rho_s / (1 - rho_i rho_s) is the corpus's."""

import pathlib

import numpy as np
import pytest

from internal_reflectance import scatmech_grid
from spacepol.physics import Geometry, Model
from spacepol.physics.fresnel import hemispherical_internal_reflectance

CORPUS = np.load(pathlib.Path(__file__).parent / "data" / "forward_corpus.npz")
MODELS = sorted({key.split("/")[0] for key in CORPUS.files if key.count("/") == 0 and key.startswith("model")})
RTOL = 1e-12


def cases(model_key):
    prefixes = sorted({key.rsplit("/", 1)[0] for key in CORPUS.files if key.startswith(model_key + "/") and key.endswith("/dop")})
    for prefix in prefixes:
        params = {key.rsplit("/", 1)[1]: CORPUS[key] for key in CORPUS.files if key.startswith(prefix + "/param/")}
        params = {k: (float(v) if v.ndim == 0 else v) for k, v in params.items()}
        if "rho_s" in params:  # x / (1 - rho_i x) = c, c = rho_s / (1 - rho_i_grid rho_s)
            c = params["rho_s"] / (1.0 - scatmech_grid(params["n"]) * params["rho_s"])
            params["rho_s"] = c / (1.0 + np.asarray(hemispherical_internal_reflectance(params["n"])) * c)
        ti, tr, dphi, wl = CORPUS[prefix + "/geometry"]
        yield prefix, params, Geometry(ti, tr, dphi, wl)


def close(new, old, scale):
    """|new - old| <= 1e-12 (|old| + the example's largest value of that output): an element that is a difference of
    nearly equal numbers (S1 near N = 1, an M_ij that should be 0, a DOP near 0) has no relative precision."""
    return np.abs(new - old) <= RTOL * (np.abs(old) + scale)


@pytest.mark.parametrize("model_key", MODELS)
def test_jax_model_equals_the_previous_implementation(model_key):
    model = Model.from_string(str(CORPUS[model_key]))
    n_cases, failures = 0, []
    for prefix, params, geometry in cases(model_key):
        stokes = model.evaluate(params, geometry)
        full = model.evaluate(params, geometry, mueller=True)
        s0 = np.max(CORPUS[prefix + "/stokes"][0])
        for name, new, old, scale in [
            ("stokes", stokes.stokes, CORPUS[prefix + "/stokes"], s0),
            ("dop", stokes.dop, CORPUS[prefix + "/dop"], np.max(CORPUS[prefix + "/dop"])),
            ("dop alone (Model.dop)", model.dop(params, geometry), CORPUS[prefix + "/dop"], np.max(CORPUS[prefix + "/dop"])),
            ("mueller", full.mueller, CORPUS[prefix + "/mueller"], np.max(CORPUS[prefix + "/mueller"][0, 0])),
            ("mueller_dop", full.dop, CORPUS[prefix + "/mueller_dop"], np.max(CORPUS[prefix + "/mueller_dop"])),
        ]:
            ok = close(new, old, scale)
            if not ok.all():
                failures.append(f"{prefix} {name}: {np.count_nonzero(~ok)} of {ok.size} differ; worst relative "
                                f"{np.max(np.abs(new - old)[~ok] / (np.abs(old[~ok]) + scale)):.3g}")
        n_cases += 1
    assert not failures, "\n".join(failures)
    assert n_cases >= 40


def test_the_comparison_can_fail():
    """Negative control: a model evaluated at a parameter 1e-9 away from the corpus's fails the check."""
    prefix, params, geometry = next(cases(MODELS[0]))
    params = {**params, "n": params["n"] * (1 + 1e-9)}
    new = Model.from_string(str(CORPUS[MODELS[0]])).evaluate(params, geometry, mueller=True).mueller
    old = CORPUS[prefix + "/mueller"]
    assert not close(new, old, np.max(old[0, 0])).all()
