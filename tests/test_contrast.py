"""`invert-mcmc contrast`: posterior -> Table 3 distributions; scenario files; bad input."""

import json

import arviz as az
import numpy as np
import pytest

from spacepol.detect.scenario import read_scenario
from spacepol.physics import Model
from spacepol.physics.geometry import Geometry
from cli_runner import run_cli

TRUTH = {"n": 1.5, "k": 0.0, "sigma": 0.25, "ks": 0.6, "rho_d": 0.3}


def _run_dir(tmp_path, spread=0.0, seed=0):
    """A run folder as `invert-mcmc run` writes it: summary.json + posterior.nc (4 chains x 250 draws)."""
    rng = np.random.default_rng(seed)
    run = tmp_path / "run"
    run.mkdir()
    post = {k: v + spread * rng.standard_normal((4, 250)) * (0.05 if k != "k" else 0.0) for k, v in TRUTH.items()}
    az.from_dict(posterior=post).to_netcdf(str(run / "posterior.nc"))
    (run / "summary.json").write_text(json.dumps({"model": "specular+shadowing+body", "fixed": {}}))
    return run


def _cli(*args, cwd=None):
    """The command line in this process (``cli_runner``): its exit status, stdout and stderr."""
    return run_cli(*args, cwd=cwd)


def test_contrast_of_a_point_posterior_is_exact(tmp_path):
    """Every draw at the truth, theta_r and the sky DOP fixed: target DOP = the model's, contrast = ratio."""
    run = _run_dir(tmp_path)
    scenario = tmp_path / "s.toml"
    scenario.write_text('[[cases]]\nname = "fixed"\nzenith_deg = 40\nazimuth_deg = 100\nsky_dop = 0.4\ntheta_r_deg = "55 deg"\n')
    r = _cli("contrast", run, "--scenario", scenario, "--draws", 500, "--out", tmp_path / "c")
    assert r.returncode == 0, r.stderr
    report = json.loads((tmp_path / "c" / "contrast.json").read_text())
    assert set(report) >= {"radiometry", "rows"}
    assert set(report["radiometry"]) >= {"N_s", "N_B", "noise", "snr"}
    row = report["rows"][0]
    assert set(row) >= {"case", "target_dop", "sky_dop", "limiting_magnitude", "intensity_contrast", "polarization_contrast"}
    for q in ("target_dop", "sky_dop", "limiting_magnitude", "intensity_contrast", "polarization_contrast"):
        assert set(row[q]) >= {"median", "q05", "q95"}
    dop = float(Model.from_string("paper").evaluate(TRUTH, Geometry(np.array([30.0]), np.array([55.0]), np.array([180.0]))).dop[0])
    assert row["target_dop"]["q05"] == pytest.approx(dop, rel=1e-3) == row["target_dop"]["q95"]
    assert row["polarization_contrast"]["median"] == pytest.approx(dop / 0.4, rel=1e-3)
    assert report["radiometry"]["snr"] == pytest.approx(7.54, abs=0.01)
    for name in ("table3.md", "contrast_histograms.png", "report.html"):
        assert (tmp_path / "c" / name).stat().st_size > 0


def test_sky_spread_follows_p_max_and_dominance_is_named(tmp_path):
    """P_max ~ U(0.6, 0.8): the sky DOP's 5 and 95 % points are the sky's unit DOP times 0.61 and 0.79 (Monte-Carlo
    error of a 5 % quantile from 20000 draws: ~0.002 relative)."""
    from spacepol.skylight.rayleigh import RayleighSky
    from spacepol.skylight.sun import sun_position

    run = _run_dir(tmp_path, spread=1.0)
    scenario = tmp_path / "s.toml"
    scenario.write_text('[sky]\np_max_low = 0.6\np_max_high = 0.8\n[[cases]]\nzenith_deg = 30\nazimuth_deg = 250\n')
    r = _cli("contrast", run, "--scenario", scenario, "--out", tmp_path / "c", "--reading", "paper")
    assert r.returncode == 0, r.stderr
    row = json.loads((tmp_path / "c" / "contrast.json").read_text())["rows"][0]
    sun = sun_position(43 + 8 / 60, 125 + 32 / 60, "2020-12-16T11:42:00+08:00")
    unit = float(RayleighSky(1.0).dop(30, 250, (sun.zenith_deg, sun.azimuth_deg)))
    assert row["sky_dop"]["q05"] == pytest.approx(0.61 * unit, rel=0.005)
    assert row["sky_dop"]["q95"] == pytest.approx(0.79 * unit, rel=0.005)
    assert row["dominant_input"]["polarization_contrast"] in ("material posterior", "target geometry (theta_r)", "sky P_max")
    assert row["limiting_magnitude"]["q95"] > row["limiting_magnitude"]["q05"]  # paper reading: P_s moves the limit
    assert "dominates" in r.stdout


@pytest.mark.parametrize("content, message", [
    ("[instrument]\npupil_areaa_m2 = 2.5\n", "unknown key(s) pupil_areaa_m2"),
    ('[instrument]\nintegration_time_s = "25 m"\n', "unit m cannot be converted to s"),
    ("[instrument]\npupil_area_m2 = -2.5\n", "'pupil_area_m2' = -2.5 must be > 0"),
    ("[instrument]\nquantum_efficiency = 1.3\n", "must lie in [0, 1]"),
    ("[telescope]\nx = 1\n", "unknown section(s) telescope"),
    ("[[cases]]\nzenith_deg = 100\nazimuth_deg = 0\n", "above the horizon"),
    ("[instrument\n", "not valid TOML"),
])
def test_bad_scenario_files_get_one_clear_line_and_exit_2(tmp_path, content, message):
    run = _run_dir(tmp_path)
    bad = tmp_path / "bad.toml"
    bad.write_text(content)
    r = _cli("contrast", run, "--scenario", bad, "--out", tmp_path / "c")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert message in r.stderr and str(bad) in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "c").exists()


def test_units_convert_and_missing_run_is_clear(tmp_path):
    good = tmp_path / "g.toml"
    good.write_text('[instrument]\nintegration_time_s = "25 ms"\npupil_area_m2 = "25440 cm2"\n')
    s = read_scenario(good)
    assert s.instrument["integration_time_s"] == pytest.approx(0.025)
    assert s.instrument["pupil_area_m2"] == pytest.approx(2.544)
    r = _cli("contrast", tmp_path / "nowhere")
    assert r.returncode == 2 and "not a folder" in r.stderr and len(r.stderr.strip().splitlines()) == 1


SPECTRAL_TRUTH = {"n@0.532": 2.2, "k@0.532": 0.0, "n@1.064": 1.3, "k@1.064": 0.1, "sigma": 0.25, "ks": 0.6, "rho_d": 0.3}


def _two_wavelength_run_dir(tmp_path):
    """A two-wavelength run folder as `invert-mcmc run` now writes it: the whole model in summary.json's "spec"."""
    run = tmp_path / "run2"
    run.mkdir()
    post = {k: np.full((4, 250), v) for k, v in SPECTRAL_TRUTH.items()}
    az.from_dict(posterior=post).to_netcdf(str(run / "posterior.nc"))
    spec = {"effects": ["specular", "shadowing", "body"], "plugins": {}, "wavelengths_um": [0.532, 1.064], "dispersion": {}}
    (run / "summary.json").write_text(json.dumps({"model": "specular+shadowing+body", "spec": spec, "fixed": {}}))
    return run


def _scenario(tmp_path, wavelength):
    scenario = tmp_path / f"s{wavelength}.toml"
    scenario.write_text(f'[target]\nwavelength_um = {wavelength}\n[[cases]]\nname = "fixed"\nzenith_deg = 40\n'
                        'azimuth_deg = 100\nsky_dop = 0.4\ntheta_r_deg = 55\n')
    return scenario


def _target_dop(tmp_path, run, wavelength, extrapolate=False):
    """contrast.json of the run at the scenario's wavelength, through the library (the command line is the
    same call: test_contrast_of_a_point_posterior_is_exact)."""
    from spacepol.infer.result import Result
    from spacepol.report.contrast_report import make_contrast_report

    return make_contrast_report(Result.load(run), read_scenario(_scenario(tmp_path, wavelength)), tmp_path / f"c{wavelength}{extrapolate}",
                                draws=200, extrapolate=extrapolate)


def _paper_dop(n, k):
    values = {"n": n, "k": k, **{p: SPECTRAL_TRUTH[p] for p in ("sigma", "ks", "rho_d")}}
    return float(Model.from_string("paper").evaluate(values, Geometry(np.array([30.0]), np.array([55.0]), np.array([180.0]))).dop[0])


def test_contrast_of_a_two_wavelength_run_uses_that_runs_n_and_k(tmp_path):
    """n, k at the scenario's wavelength come from the run (as measured, or interpolated between the measured
    wavelengths), never from the model's defaults (n = 1.5, k = 0); outside the measured range one line and
    exit 2 unless --extrapolate. The DOPs at the two wavelengths differ by far more than the tolerance."""
    run = _two_wavelength_run_dir(tmp_path)
    at_532, at_1064, default = _paper_dop(2.2, 0.0), _paper_dop(1.3, 0.1), _paper_dop(1.5, 0.0)
    assert min(abs(at_532 - at_1064), abs(at_532 - default), abs(at_1064 - default)) > 0.02
    report = _target_dop(tmp_path, run, 0.532)
    assert report["rows"][0]["target_dop"]["median"] == pytest.approx(at_532, rel=1e-3)
    assert report["material"]["wavelength_um"] == 0.532 and "as measured at 0.532" in report["material"]["rule"]
    report = _target_dop(tmp_path, run, 0.798)  # halfway: n 1.75, k 0.05
    assert report["rows"][0]["target_dop"]["median"] == pytest.approx(_paper_dop(1.75, 0.05), rel=1e-3)
    assert "interpolated" in report["material"]["rule"]
    r = _cli("contrast", run, "--scenario", _scenario(tmp_path, 1.65), "--draws", 200, "--out", tmp_path / "c1.65")
    assert r.returncode == 2 and "outside the run's measured 0.532-1.064 um" in r.stderr and "--extrapolate" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and not (tmp_path / "c1.65").exists()
    report = _target_dop(tmp_path, run, 1.65, extrapolate=True)
    assert report["rows"][0]["target_dop"]["median"] == pytest.approx(at_1064, rel=1e-3)
    assert report["material"]["extrapolated"] is True and "nearest measured wavelength 1.064" in report["material"]["rule"]
