"""Table 3 as distributions: posterior samples of the material -> target DOP at the scenario's
geometry -> limiting magnitude, intensity and polarization contrast against the sky.

Sources of spread, drawn jointly (``draws`` Monte-Carlo draws, one Generator):
* the material: a posterior sample of the run (its parameters);
* the target geometry: theta_r uniform in the scenario's range (the paper takes the DOP range of
  its Figure 9 over theta_r), unless a case fixes ``theta_r_deg``;
* the sky: P_max uniform in [p_max_low, p_max_high], unless a case fixes ``sky_dop``.
The paper's reading and the corrected one (``radiometry.READINGS``) differ in the limiting
magnitude only.
"""

from __future__ import annotations

import numpy as np

from ..physics.geometry import Geometry
from ..skylight.neutral_points import BerryDennisLeeSky
from ..skylight.rayleigh import RayleighSky
from ..skylight.sun import sun_position
from . import radiometry as R
from .table3_chain import chain_limit

THETA_R_GRID = 81


def interval(x) -> dict:
    """Median and 5-95 % interval of draws."""
    q = np.percentile(np.asarray(x, float), [5, 50, 95])
    return {"median": float(q[1]), "q05": float(q[0]), "q95": float(q[2])}


def sky_model(scenario, p_max):
    """The scenario's sky model (Rayleigh or Berry-Dennis-Lee) with this P_max."""
    if scenario.sky["model"] == "berry-dennis-lee":
        return BerryDennisLeeSky(p_max, scenario.sky["delta_deg"])
    return RayleighSky(p_max)


def scenario_wavelength_um(scenario) -> float:
    """The wavelength the target is seen at: [target] wavelength_um, else the instrument band's centre."""
    given = scenario.target.get("wavelength_um")
    inst = scenario.instrument
    return float(given) if given else 0.5 * (inst["band_low_um"] + inst["band_high_um"])


def material_samples(model, samples: dict, scenario, spec, extrapolate: bool = False):
    """(one-wavelength model, {parameter: posterior draws} at the scenario's wavelength, contrast.json's
    ``material`` record: the wavelength, the run's wavelengths and the rule that gave n and k there).

    A run over several wavelengths gives n, k at the scenario's wavelength from its dispersion law or by linear
    interpolation between the measured wavelengths around it (``SpectralModel.values_at_wavelength``); outside
    the measured range only with ``extrapolate``. A one-wavelength run's draws are used as measured (``spec``: the
    run's stored model spec, which names its wavelength; a bare model name does not)."""
    from ..errors import SpacepolError
    from ..physics.spectral import SpectralModel

    lam = scenario_wavelength_um(scenario)
    if isinstance(model, SpectralModel):
        try:
            params, rule = model.values_at_wavelength(samples, lam, extrapolate)
        except SpacepolError as exc:
            raise SpacepolError(f"contrast: the scenario's {exc} (set [target] wavelength_um in the scenario, or pass "
                                "--extrapolate: extrapolate=True in the API)") from None
        return model.model, params, {"wavelength_um": lam, "measured_wavelengths_um": list(model.wavelengths),
                                     "rule": rule, "extrapolated": not (model.wavelengths[0] <= lam <= model.wavelengths[-1])}
    measured = spec.get("wavelengths_um") if isinstance(spec, dict) else None
    at = f" at {measured[0]:g} um" if measured else ""
    return model, samples, {"wavelength_um": lam, "measured_wavelengths_um": measured,
                            "rule": f"the run's one-wavelength posterior{at} used as measured (no dispersion to "
                                    f"{lam:g} um modelled)", "extrapolated": bool(measured) and abs(measured[0] - lam) > 1e-9}


def contrast_of(result, scenario, seed: int = 0, draws: int = 20000, reading: str = "corrected",
                extrapolate: bool = False) -> tuple[dict, dict]:
    """(contrast.json's content, {case: {quantity: draws}}) of a run's Result (``infer.result``) in ``scenario``: the
    Result's own model (rebuilt from its stored spec) and draws; over several wavelengths n, k at the scenario's
    wavelength (``material_samples``). The content's ``material`` says which rule gave them; ``seed`` seeds the one
    Generator of the propagation."""
    from ..errors import SpacepolError
    from .paper_table3 import recompute

    samples, spec = result.samples(), result.summary.model_spec
    if isinstance(spec, str) and any("@" in name for name in samples):
        raise SpacepolError("contrast: the run has per-wavelength parameters but its summary.json stores only the model's "
                            "name; run it again with this version to store the whole model")
    inner, params, material = material_samples(result.model, samples, scenario, spec, extrapolate)
    report = propagate(inner, params, scenario, np.random.default_rng(seed), draws=draws, reading=reading)
    per_case = report.pop("draws_by_case")
    report.update(material=material, paper_table3=recompute(scenario.instrument), model=spec, seed=seed)
    return report, per_case


def target_dop_grid(model, samples: dict, scenario) -> tuple[np.ndarray, np.ndarray]:
    """DOP of every posterior sample on a theta_r grid: (theta_r (G,), dop (S, G))."""
    t = scenario.target
    theta_r = np.linspace(t["theta_r_low_deg"], t["theta_r_high_deg"], THETA_R_GRID)
    geometry = Geometry(np.full(theta_r.shape, t["theta_i_deg"]), theta_r, np.full(theta_r.shape, t["dphi_deg"]))
    names = {p.name for p in model.parameters}
    params = {k: np.asarray(v, float) for k, v in samples.items() if k in names}
    return theta_r, model.dop(params, geometry)


def _draw_target(theta_r, grid, rng, draws, fixed_theta_r=None, sample_index=None):
    s = rng.integers(grid.shape[0], size=draws) if sample_index is None else np.full(draws, sample_index)
    tr = rng.uniform(theta_r[0], theta_r[-1], draws) if fixed_theta_r is None else np.full(draws, fixed_theta_r)
    pos = np.interp(tr, theta_r, np.arange(theta_r.size))
    lo = np.floor(pos).astype(int).clip(0, theta_r.size - 2)
    w = pos - lo
    return (1 - w) * grid[s, lo] + w * grid[s, lo + 1]


def _draw_sky(scenario, case, sun, rng, draws, fixed_p_max=None):
    if "sky_dop" in case:
        return np.full(draws, case["sky_dop"])
    lo, hi = scenario.sky["p_max_low"], scenario.sky["p_max_high"]
    p_max = rng.uniform(lo, hi, draws) if fixed_p_max is None else np.full(draws, fixed_p_max)
    unit = sky_model(scenario, 1.0).dop(case["zenith_deg"], case["azimuth_deg"], (sun.zenith_deg, sun.azimuth_deg))
    return p_max * float(unit)


def case_rows(p_target, p_sky, scenario, reading):
    """Target DOP, sky DOP, limiting magnitude and the two contrasts for draws of target and sky DOP."""
    inst = scenario.instrument
    m_lim = R.limiting_magnitude(p_target, inst, reading)
    return {"target_dop": p_target, "sky_dop": p_sky, "limiting_magnitude": m_lim,
            "intensity_contrast": R.intensity_contrast(m_lim, inst["sky_magnitude"]),
            "polarization_contrast": R.polarization_contrast(p_target, p_sky)}


def propagate(model, samples: dict, scenario, rng: np.random.Generator, draws: int = 20000,
              reading: str = "corrected") -> dict:
    """contrast.json's content (DESIGN fields) plus the draws themselves under ``draws_by_case``."""
    sun = sun_position(scenario.site["lat_deg"], scenario.site["lon_deg"], scenario.site["time"])
    theta_r, grid = target_dop_grid(model, samples, scenario)
    inst = scenario.instrument
    rows, draws_out = [], {}
    for case in scenario.cases:
        p_t = _draw_target(theta_r, grid, rng, draws, case.get("theta_r_deg"))
        p_b = _draw_sky(scenario, case, sun, rng, draws)
        values = case_rows(p_t, p_b, scenario, reading)
        row = {"case": case["name"], "zenith_deg": case["zenith_deg"], "azimuth_deg": case["azimuth_deg"]}
        row.update({k: interval(v) for k, v in values.items()})
        row["dominant_input"] = dominance(theta_r, grid, scenario, case, sun, rng, draws, reading)
        rows.append(row)
        draws_out[case["name"]] = values
    p_sky_mid = float(np.median(draws_out[scenario.cases[0]["name"]]["sky_dop"])) if scenario.cases else 0.0
    flux = inst["limit_flux_photons_m2_s"]
    n_s = R.target_electrons(flux, inst)
    n_b = R.background_electrons(inst, p_sky_mid, "paper" if reading == "paper" else "corrected")
    noise = R.noise_electrons(n_s, n_b, inst)
    return {
        "reading": reading, "scenario": scenario.source, "draws": draws,
        "sun": {"zenith_deg": sun.zenith_deg, "azimuth_deg": sun.azimuth_deg, "time_utc": sun.time_utc},
        "radiometry": {"N_s": float(n_s), "N_B": float(n_b), "noise": float(noise), "snr": float(n_s / noise),
                       "limit_flux_photons_m2_s": flux, "limit_flux_for_required_snr": float(R.limit_flux(inst)),
                       "magnitude_of_limit_flux": float(R.magnitude(flux, inst))},
        "rows": rows, "draws_by_case": draws_out,
        # the same limit asked of the pass chain's detector (detect.table3_chain): how the two compare
        "limit_through_chain": chain_limit(inst, p_sky_mid),
    }


def dominance(theta_r, grid, scenario, case, sun, rng, draws, reading) -> dict:
    """Width of the 90 % interval of the polarization contrast and the limiting magnitude when only
    one input varies (the others at their middle): which input dominates the spread."""
    mid_theta = float(case.get("theta_r_deg", 0.5 * (theta_r[0] + theta_r[-1])))
    mid_pmax = 0.5 * (scenario.sky["p_max_low"] + scenario.sky["p_max_high"])
    median_sample = int(np.argsort(grid[:, theta_r.size // 2])[grid.shape[0] // 2])
    variants = {
        "material posterior": (_draw_target(theta_r, grid, rng, draws, mid_theta), _draw_sky(scenario, case, sun, rng, draws, mid_pmax)),
        "target geometry (theta_r)": (_draw_target(theta_r, grid, rng, draws, case.get("theta_r_deg"), median_sample),
                                      _draw_sky(scenario, case, sun, rng, draws, mid_pmax)),
        "sky P_max": (_draw_target(theta_r, grid, rng, draws, mid_theta, median_sample), _draw_sky(scenario, case, sun, rng, draws)),
    }
    widths = {}
    for name, (p_t, p_b) in variants.items():
        v = case_rows(p_t, p_b, scenario, reading)
        widths[name] = {k: float(np.diff(np.percentile(v[k], [5, 95]))[0]) for k in ("polarization_contrast", "limiting_magnitude")}
    lead = max(widths, key=lambda n: widths[n]["polarization_contrast"])
    return {"widths_90": widths, "polarization_contrast": lead}
