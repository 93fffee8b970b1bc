"""docs/tutorial.md runs as written, through the top-level API only, and its round trip (invert -> save ->
Result.load -> contrast) on a two-wavelength set uses that run's n and k at the scenario's wavelength."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

TUTORIAL = Path(__file__).resolve().parents[1] / "docs" / "tutorial.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", TUTORIAL.read_text(encoding="utf-8"), flags=re.S)


@pytest.fixture(scope="module")
def tutorial():
    """The tutorial's namespace after running it; its working folder (a temporary folder it makes) removed after."""
    namespace: dict = {"__name__": "tutorial"}
    try:
        for block in _blocks():
            exec(compile(block, str(TUTORIAL), "exec"), namespace)
        yield namespace
    finally:
        if "work" in namespace:
            shutil.rmtree(namespace["work"], ignore_errors=True)


def test_the_tutorial_uses_only_the_top_level_api():
    """No ``spacepol.<module>`` attribute path and no ``from spacepol... import``: what a notebook user sees."""
    code = "\n".join(_blocks())
    assert len(_blocks()) >= 5
    assert not re.search(r"from\s+spacepol", code)
    import spacepol

    used = set(re.findall(r"spacepol\.(\w+)", code))
    assert used and used <= set(spacepol.__all__), used - set(spacepol.__all__)
    # control: the check sees a submodule path
    assert not set(re.findall(r"spacepol\.(\w+)", "spacepol.infer.inversion.invert(x)")) <= set(spacepol.__all__)


def test_tutorial_recovers_the_truth_and_its_round_trip_uses_the_runs_own_n_and_k_at_the_scenario_wavelength(tutorial):
    """The inversion in the tutorial finds the index it was made with (within 4 posterior SD); its draws survive
    save -> Result.load, and the contrast of the loaded Result uses its n and k interpolated to the scenario's
    wavelength. (One test: the tutorial's run is its costliest part, made once.)"""
    import spacepol

    result, again, table = tutorial["result"], tutorial["again"], tutorial["table"]
    s = result.samples()
    for lam, (n, _) in tutorial["index"].items():
        draws = s[f"n@{lam:g}"]
        assert abs(np.median(draws) - n) < 4 * np.std(draws)
    assert isinstance(again, spacepol.Result) and again.posterior is None
    assert again.spec["wavelengths_um"] == [0.532, 1.064] and again.spec["effects"] == result.spec["effects"]
    for name, values in result.samples().items():  # the draws survive the round trip
        np.testing.assert_allclose(again.samples()[name], values, rtol=1e-12)
    assert again.diagnostics == result.diagnostics and again.log_evidence == result.log_evidence
    # Laplace-IS gives the evidence where its checks trust it; emcee, where they refuse it, none
    assert (result.log_evidence is not None) == (result.diagnostics.engine == "laplace-is"), result.summary.laplace_refused
    assert "interpolated" in table.material["rule"] and table.material["wavelength_um"] == 0.8

    # the target DOP the contrast should find, computed here from the loaded draws: n, k interpolated linearly in
    # wavelength per draw, the paper's DOP at the scenario's fixed geometry (theta_i 30, theta_r 55, dphi 180)
    s = again.samples()
    w = (0.8 - 0.532) / (1.064 - 0.532)
    geometry = spacepol.Geometry(np.array([30.0]), np.array([55.0]), np.array([180.0]))
    model = spacepol.Model.from_string("paper")

    def dop(n, k):
        params = {"n": n, "k": k, **{p: s[p] for p in ("sigma", "ks", "rho_d")},
                  **{p: np.full(n.shape, float(s[p])) for p in model.defaults() if p not in ("n", "k", "sigma", "ks", "rho_d")}}
        return np.asarray(model.dop(params, geometry))[:, 0]

    expected = dop((1 - w) * s["n@0.532"] + w * s["n@1.064"], (1 - w) * s["k@0.532"] + w * s["k@1.064"])
    got = table.rows[0]["target_dop"]["median"]
    # Monte-Carlo error of a median of 4,000 resampled draws: 1.2533 SD / sqrt(4000); four of them
    tolerance = 4 * 1.2533 * np.std(expected) / np.sqrt(table.content["draws"])
    assert got == pytest.approx(np.median(expected), abs=tolerance)
    # controls: the model's defaults (n 1.5, k 0) and the run's values at 1.064 um alone are both far outside it
    for wrong in (dop(np.full_like(expected, 1.5), np.zeros_like(expected)), dop(s["n@1.064"], s["k@1.064"])):
        assert abs(np.median(wrong) - got) > 10 * tolerance
