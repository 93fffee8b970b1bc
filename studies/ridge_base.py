"""What the ridge studies (``emcee_cap_elpd.py``, ``elpd_settled_stop.py``) share: the 278-geometry PTFE set of
``benchmarks/diagnose_rounds_speed.py`` at 0.633 um, and the pointwise ELPD-LOO of ``paper+lambertian`` on it
(diagnose's round-2 base, fitted as diagnose fits it)."""

import numpy as np

BASE = "paper+lambertian"


def ptfe_set():
    """NIST's PTFE at 0.633 um: every k-th geometry (about 260) and every row of a reciprocal pair."""
    from spacepol.infer.measured_noise import reciprocal_pairs
    from spacepol.io import read_measurements
    from spacepol.paths import bundled

    first = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    rows = np.union1d(np.arange(0, len(first), max(1, len(first) // 260)), reciprocal_pairs(first).ravel())
    return first.select(rows)


def base_pointwise(data) -> np.ndarray:
    """``BASE``'s pointwise ELPD-LOO on ``data`` (its global multistart's optimum, then diagnose's refit), printed."""
    from spacepol.criticism.candidate_fits import _build, fit_for_elpd
    from spacepol.infer.optimum import multistart
    from spacepol.physics import Model

    base = _build(data, Model.from_string(BASE), None, None)
    _, centre = multistart(base, np.random.default_rng(0))
    out = fit_for_elpd(base, centre, 0, 8000).loo["pointwise"]
    print(f"{BASE}: ELPD-LOO {out.sum():.1f} (Laplace-IS)", flush=True)
    return out
