"""Index-like parameters told honestly (``infer.indices``): determined or not by the width of the 90 % interval,
physical or not against the material's band."""

from spacepol.infer.indices import DETERMINED_WIDTH, index_findings, unphysical

BAND = (1.15, 1.45)  # porous PTFE


def _q(median, lo, hi):
    return {"median": median, "q05": lo, "q95": hi}


def test_each_index_is_judged_by_its_width_and_its_band():
    parameters = {"n": _q(0.655, 0.637, 0.673), "n@0.633": _q(1.30, 1.28, 1.32), "n_pm": _q(1.5, 1.1, 1.9),
                  "sigma": _q(0.2, 0.19, 0.21), "n_film@1.064": _q(1.46, 1.44, 1.48)}
    found = {f.name: f for f in index_findings(parameters, BAND)}
    assert set(found) == {"n", "n@0.633", "n_pm", "n_film@1.064"}  # sigma is no index
    assert found["n"].determined and found["n"].physical is False and "UNPHYSICAL" in found["n"].text
    assert found["n@0.633"].physical is True and "physical (inside" in found["n@0.633"].text
    assert not found["n_pm"].determined and found["n_pm"].physical is None and "not determined" in found["n_pm"].text
    assert found["n_film@1.064"].physical is True  # its interval reaches the band
    assert [f.name for f in unphysical(list(found.values()))] == ["n"]


def test_the_width_limit_is_strict_and_no_band_judges_nothing():
    at_limit = index_findings({"n": _q(1.3, 1.0, 1.0 + DETERMINED_WIDTH)}, BAND)[0]
    assert not at_limit.determined
    unjudged = index_findings({"n": _q(0.6, 0.59, 0.61)})[0]
    assert unjudged.determined and unjudged.physical is None and unphysical([unjudged]) == []
